#include "common/json_reader.h"

#include <gtest/gtest.h>

namespace irbench {
namespace {

TEST(JsonReaderTest, ErrorsNameFileAndField) {
  const JsonNode root = ParseJsonString(R"({"a": {"b": [1, "x"]}})", "f.json");
  EXPECT_EQ(root["a"]["b"][0].Number(), 1.0);
  try {
    root["a"]["b"][1].Number();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "f.json");
    EXPECT_EQ(e.field(), "a.b[1]");
  }
  try {
    root["a"]["c"];
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "a.c");
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos);
  }
}

TEST(JsonReaderTest, TruncatedJsonNamesTheLine) {
  try {
    ParseJsonString("{\n \"a\": [1,\n 2", "t.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "t.json");
    EXPECT_EQ(e.field(), "line 3");
  }
}

TEST(JsonReaderTest, UnknownKeysAreRejected) {
  const JsonNode root = ParseJsonString(R"({"fx": 1, "fxx": 2})", "k.json");
  try {
    root.CheckKeys({"fx"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "fxx");
  }
}

}  // namespace
}  // namespace irbench
