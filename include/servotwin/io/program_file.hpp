#pragma once
/// \file
/// G-code files: reading a file and handing its text to the motion readers.

#include <optional>
#include <string>

#include "servotwin/motion/gcode.hpp"

namespace servotwin::io {

/// Reads the whole text file (core::InputError naming the file when it cannot be read, is a
/// directory, or is larger than `max_bytes`).
std::string read_text_file(const std::string& path, std::size_t max_bytes = std::size_t{1} << 30);

/// Reads and parses a part program; the dialect is detected unless given.
motion::Program read_program_file(const std::string& path, const motion::ParseOptions& options = {},
                                  std::optional<motion::Dialect> dialect = std::nullopt);

}  // namespace servotwin::io
