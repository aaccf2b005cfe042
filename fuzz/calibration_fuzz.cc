// libFuzzer harness: the calibration reader (sequence_format/calibration.h,
// ReadCalibration). An input is intri.yml, extri.yml and cameras.json joined by
// the separator (fuzz/fuzz_input.h), written as calib/ of a scratch sequence
// folder. Corpus: fuzz/corpus/calibration; dictionary: fuzz/calibration.dict.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "fuzz/fuzz_input.h"
#include "sequence_format/calibration.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbench::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = irbench::fuzz::SplitParts(data, size, 3);
  irbench::fuzz::WriteScratchFile(irbench::kIntriFile, parts[0]);
  irbench::fuzz::WriteScratchFile(irbench::kExtriFile, parts[1]);
  irbench::fuzz::WriteScratchFile(irbench::kCamerasFile, parts[2]);
  try {
    irbench::ReadCalibration(irbench::fuzz::ScratchDir());
  } catch (const std::exception&) {
    // Bad input is answered with an exception: not a finding.
  }
  return 0;
}
