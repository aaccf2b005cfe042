// libFuzzer harness: the BVH reader (sim/motion/bvh.h) and forward kinematics
// on what it accepts. Corpus: fuzz/corpus/bvh; dictionary: fuzz/bvh.dict.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "fuzz/fuzz_input.h"
#include "sim/motion/bvh.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbench::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const irbench::BvhFile bvh = irbench::ParseBvh(text, "fuzz.bvh");
    irbench::BvhToClip(bvh);
    irbench::WriteBvh(bvh);
  } catch (const std::exception&) {
    // Bad input is answered with an exception: not a finding.
  }
  return 0;
}
