// libFuzzer harness: the rig reader (sim/camera/rig.h, LoadRig) on JSON bytes
// written to a scratch file. Corpus: fuzz/corpus/rig; dictionary: fuzz/json.dict.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string_view>

#include "fuzz/fuzz_input.h"
#include "sim/camera/rig.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbench::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    irbench::LoadRig(irbench::fuzz::WriteScratchFile("rig.json", bytes));
  } catch (const std::exception&) {
    // Bad input is answered with an exception: not a finding.
  }
  return 0;
}
