#pragma once
// Checks on the command line's numbers and paths, shared by the subcommands.
// Integers are read from their text: CLI11 alone would wrap `--seed -1` into
// an unsigned, clamp what overflows 64 bits, and read `010` as octal; here a
// value that is not a decimal integer in the option's range is refused with
// one line naming the option (exit 2).

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <utility>

namespace irbench::cli {

// A CLI11 transform: the text is a decimal integer (no sign for unsigned
// ranges, no base prefix) in [min, max]; rewritten without leading zeros.
CLI::Validator IntegerIn(long long min, long long max);

// The same for a 64-bit unsigned option (seeds): 0..18446744073709551615.
CLI::Validator Uint64Text();

// Throws InputError naming `option` when it was given but empty (`--out ''`
// would otherwise mean "the default folder").
void RequireNotEmpty(const CLI::App& cmd, const std::string& option, const std::string& value);

// --empty-stage's "FROM:TO" (seconds, 0 <= FROM < TO); InputError otherwise.
std::pair<double, double> ParseEmptyStage(const std::string& text);

}  // namespace irbench::cli
