// libFuzzer harness: the ASF/AMC reader (sim/motion/asf_amc.h), skeleton and
// motion with forward kinematics. An input is the ASF text, the separator
// (fuzz/fuzz_input.h) and the AMC text. Corpus: fuzz/corpus/asf_amc;
// dictionary: fuzz/asf_amc.dict.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "fuzz/fuzz_input.h"
#include "sim/motion/asf_amc.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbench::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = irbench::fuzz::SplitParts(data, size, 2);
  try {
    irbench::ParseAsfAmc(parts[0], "fuzz.asf", parts[1], "fuzz.amc");
  } catch (const std::exception&) {
    // Bad input is answered with an exception: not a finding.
  }
  return 0;
}
