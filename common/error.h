#pragma once
// Typed errors for the CLI's exit codes: InputError (exit 2) names the file and
// field of bad input; RuntimeError (exit 1) is a failure of the machine or the
// environment (no GL context, disk full).

#include <stdexcept>
#include <string>

namespace irbench {

class InputError : public std::runtime_error {
 public:
  // `file` may be empty for command-line options; `field` is a JSON-path-like
  // location ("cameras[2].fx") or an option name ("--out").
  InputError(std::string file, std::string field, const std::string& message);

  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  // The message without the file and field.
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  std::string field_;
  std::string message_;
};

class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown when the user interrupts a long run (SIGINT/SIGTERM).
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("interrupted") {}
};

}  // namespace irbench
