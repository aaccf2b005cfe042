#include "common/json_reader.h"

#include <gtest/gtest.h>

#include <functional>

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

// Model files' matrices: sizes and finiteness checked, the bad row named.
TEST(JsonReaderTest, FiniteVectorsAndMatrices) {
  const JsonNode root = ParseJsonString(R"({"m": [[1, 2], [3, 4]], "v": [1, 2, 3], "r": [[1, 2], [3]]})", "m.json");
  EXPECT_EQ(root["m"].FiniteMatrix(2, 2), (Eigen::Matrix2d() << 1, 2, 3, 4).finished());
  EXPECT_EQ(root["v"].FiniteVector(3), Eigen::Vector3d(1, 2, 3));
  const auto field_of = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const InputError& e) {
      return e.field() + ": " + e.message();
    }
    return std::string("no error");
  };
  EXPECT_EQ(field_of([&] { root["v"].FiniteVector(2); }), "v: must have 2 values");
  EXPECT_EQ(field_of([&] { root["m"].FiniteMatrix(3, 2); }), "m: must have 3 rows");
  EXPECT_EQ(field_of([&] { root["r"].FiniteMatrix(2, 2); }), "r[1]: must have 2 values");
}

}  // namespace
}  // namespace irbench
