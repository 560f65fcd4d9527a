#include "servotwin/io/output_file.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <random>

#include "servotwin/core/error.hpp"

namespace servotwin::io {

namespace {
std::string temporary_name(const std::string& path) {
  std::random_device entropy;
  return path + ".tmp-" + std::to_string(entropy() % 1000000U);
}
}  // namespace

OutputFile::OutputFile(std::string path, Overwrite overwrite) : path_(std::move(path)) {
  if (path_ == "-") {
    to_stdout_ = true;
    return;
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path_, ec))
    throw core::InputError({path_, 0, 0, "-o"}, "is a directory, expected a file name");
  if (overwrite == Overwrite::Refuse && std::filesystem::exists(path_, ec))
    throw core::InputError({path_, 0, 0, "-o"}, "file exists; pass --force to overwrite it");
  temp_path_ = temporary_name(path_);
  file_.open(temp_path_, std::ios::binary | std::ios::trunc);
  if (!file_) throw core::InputError({path_, 0, 0, "-o"}, "cannot create the file (is the directory writable?)");
}

OutputFile::~OutputFile() {
  if (to_stdout_ || committed_) return;
  file_.close();
  std::error_code ec;
  std::filesystem::remove(temp_path_, ec);
}

std::ostream& OutputFile::stream() { return to_stdout_ ? std::cout : static_cast<std::ostream&>(file_); }

void OutputFile::commit() {
  if (to_stdout_) {
    std::cout.flush();
    committed_ = true;
    return;
  }
  file_.flush();
  const bool ok = static_cast<bool>(file_);
  file_.close();
  if (!ok) throw core::InputError({path_, 0, 0, "-o"}, "write failed (disk full?)");
  std::error_code ec;
  std::filesystem::rename(temp_path_, path_, ec);
  if (ec) throw core::InputError({path_, 0, 0, "-o"}, "cannot move the finished file into place: " + ec.message());
  committed_ = true;
}

}  // namespace servotwin::io
