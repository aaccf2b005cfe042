// libFuzzer harness: the suite reader (ci/suite_runner, irbench.suite/1) on
// JSON bytes written to a scratch file. Corpus: fuzz/corpus/suite; dictionary:
// fuzz/json.dict.
//
// The reader, ReadSuite, is private to suite.cc and RunSuite goes on to render
// and track every scenario, so this file compiles suite.cc (and scenario.cc,
// which reads each scenario's keys) itself to call it (the harness does not
// link irbench::suite). When suite.h exposes the reader,
// call that instead.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <string_view>

#include "ci/suite_runner/scenario.cc"  // NOLINT(bugprone-suspicious-include): what suite.cc calls
#include "ci/suite_runner/suite.cc"     // NOLINT(bugprone-suspicious-include): see above
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbench::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    std::string name;
    irbench::ReadSuite(irbench::fuzz::WriteScratchFile("suite.json", bytes), &name);
  } catch (const std::exception&) {
    // Bad input is answered with an exception: not a finding.
  }
  return 0;
}
