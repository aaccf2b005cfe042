// libFuzzer harness: glTF avatar import (sim/body/avatar_import.h,
// ImportRiggedAvatar), from binary (.glb) or JSON (.gltf) bytes written to a
// scratch file. Corpus: fuzz/corpus/gltf (made by fuzz/make_gltf_seeds.py);
// dictionary: fuzz/gltf.dict.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string_view>

#include "fuzz/fuzz_input.h"
#include "sim/body/avatar_import.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  irbench::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  // The name only routes the file to the glTF importer; it reads the magic.
  const bool binary = bytes.substr(0, 4) == "glTF";
  try {
    irbench::ImportRiggedAvatar(irbench::fuzz::WriteScratchFile(binary ? "avatar.glb" : "avatar.gltf", bytes));
  } catch (const std::exception&) {
    // Bad input is answered with an exception: not a finding.
  }
  return 0;
}
