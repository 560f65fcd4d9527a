#pragma once
/// \file
/// Errors that reach the user. Every reader and algorithm reports bad user input with
/// `InputError`, naming where the problem is (file, line, column or field) and what was expected.
/// The command-line tool maps `InputError` to exit status 3 and `IoError` to 4.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace servotwin::core {

/// Where a problem sits in user input. Empty/zero members are simply not printed.
struct SourceLocation {
  std::string file;        ///< file name as the user gave it (or a label such as "<stdin>")
  std::size_t line = 0;    ///< 1-based line, 0 = unknown
  std::size_t column = 0;  ///< 1-based column, 0 = unknown
  std::string field;       ///< JSON field, CSV column or option name, empty = none
};

/// A location that is a field alone (a parameter, option or JSON member), for errors in values
/// given through the API rather than read from a file.
SourceLocation at_field(std::string field);

/// Text from the user quoted in a message: printable ASCII kept, every other byte as \xHH (a control
/// byte in a file must not reach the terminal), cut after `max_chars` with "...".
std::string printable(std::string_view text, std::size_t max_chars = 40);

/// Formats a location as `file:line:column` followed by ` (field)` when a field is set.
std::string to_string(const SourceLocation& where);

/// Bad user input: malformed files, values out of range, inconsistent options.
class InputError : public std::runtime_error {
 public:
  /// `message` says what is wrong and what was expected; it is prefixed with the location.
  InputError(SourceLocation where, const std::string& message);
  /// Error without a location (e.g. a problem with a combination of options).
  explicit InputError(const std::string& message);

  [[nodiscard]] const SourceLocation& where() const noexcept { return where_; }
  /// The message without the location prefix.
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }

 private:
  SourceLocation where_;
  std::string reason_;
};

/// A file could not be written whole: a failed write, flush, close or rename (disk full, a device
/// such as /dev/full, a closed pipe). Derived from InputError for its location (the file and the
/// option that named it); the command-line tool catches it first and exits with status 4.
class IoError : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace servotwin::core
