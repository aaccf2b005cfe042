// libFuzzer harness: the scene reader (sim/scene/scene.h, LoadScene: rooms,
// boxes, screens, lights, the static mesh) on JSON bytes written to a scratch
// file. Corpus: fuzz/corpus/scene; dictionary: fuzz/json.dict.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string_view>

#include "fuzz/fuzz_input.h"
#include "sim/scene/scene.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbench::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    irbench::LoadScene(irbench::fuzz::WriteScratchFile("scene.json", bytes));
  } catch (const std::exception&) {
    // Bad input is answered with an exception: not a finding.
  }
  return 0;
}
