#include "servotwin/io/program_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "servotwin/core/error.hpp"

namespace servotwin::io {

std::string read_text_file(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw core::InputError({path, 0, 0, ""}, "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError({path, 0, 0, ""}, std::string("cannot open the file for reading: ") + std::strerror(errno));
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes)
      throw core::InputError({path, 0, 0, ""}, "file is larger than " + std::to_string(max_bytes) + " bytes");
  }
  if (in.bad()) throw core::InputError({path, 0, 0, ""}, "read error");
  return text;
}

motion::Program read_program_file(const std::string& path, const motion::ParseOptions& options,
                                  std::optional<motion::Dialect> dialect) {
  const std::string text = read_text_file(path);
  return motion::parse_program(text, path, options, dialect);
}

}  // namespace servotwin::io
