#pragma once
// What the libFuzzer harnesses share (docs/fuzzing.md): quiet logging, inputs
// split into the several files a reader takes, and a per-process scratch folder
// for readers that only take a path.
//
// A harness calls a reader and catches std::exception: InputError and
// RuntimeError (common/error.h), and what the third-party parsers throw
// (nlohmann::json, cv::Exception), are the expected answer to bad input. Only a
// crash, a sanitizer report, a leak, a timeout or an out-of-memory is a finding.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace irbench::fuzz {

// Separates the files of a multi-file input (ASF + AMC; intri.yml, extri.yml
// and cameras.json). In the dictionaries, so mutations can add and drop it.
inline constexpr std::string_view kPartSeparator = "\n----8<----\n";

// Turns the project's logger off: readers log warnings for odd input, which
// would flood the fuzzer's output and slow it down.
void QuietLogging();

// The input cut at kPartSeparator into exactly `parts` strings: missing parts
// are empty, and the last part keeps any further separators.
std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t parts);

// /tmp/irbench-fuzz-<pid>: created on first use, removed at exit. Each
// process (libFuzzer -jobs/-workers) has its own.
const std::filesystem::path& ScratchDir();

// Writes `bytes` to ScratchDir() / `name` (parents created) and returns the path.
std::filesystem::path WriteScratchFile(const std::string& name, std::string_view bytes);

}  // namespace irbench::fuzz
