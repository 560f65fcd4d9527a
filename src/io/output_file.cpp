#include "servotwin/io/output_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <random>
#include <system_error>

#include "servotwin/core/error.hpp"

namespace servotwin::io {

namespace {

std::string temporary_name(const std::string& path) {
  std::random_device entropy;
  return path + ".tmp-" + std::to_string(entropy() % 1000000U);
}

/// The reason of the failed system call, for messages ("No space left on device"). A buffered
/// stream may have failed on an earlier write whose errno is gone by the time it is checked.
std::string last_error() { return errno != 0 ? std::strerror(errno) : "data was lost (device full or closed?)"; }

}  // namespace

OutputKind output_kind(const std::string& path) {
  if (path == "-" || path == "/dev/stdout") return OutputKind::kStandardOutput;
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status) &&
      !std::filesystem::is_directory(status))
    return OutputKind::kDevice;
  return OutputKind::kRegularFile;
}

OutputFile::OutputFile(std::string path, Overwrite overwrite, std::string option, Publish publish)
    : path_(std::move(path)), option_(std::move(option)), kind_(output_kind(path_)), publish_(publish) {
  const core::SourceLocation where{path_, 0, 0, option_};
  if (kind_ == OutputKind::kStandardOutput) return;
  if (kind_ == OutputKind::kDevice) {
    errno = 0;
    file_.open(path_, std::ios::binary | std::ios::out);
    if (!file_) throw core::IoError(where, "cannot open for writing: " + last_error());
    return;
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path_, ec)) throw core::InputError(where, "is a directory, expected a file name");
  if (overwrite == Overwrite::Refuse && std::filesystem::exists(path_, ec))
    throw core::InputError(where, "file exists; pass --force to overwrite it");
  temp_path_ = temporary_name(path_);
  file_.open(temp_path_, std::ios::binary | std::ios::trunc);
  if (!file_) throw core::InputError(where, "cannot create the file (is the directory writable?)");
}

OutputFile::~OutputFile() {
  if (kind_ != OutputKind::kRegularFile || published_) return;
  file_.close();
  std::error_code ec;
  std::filesystem::remove(temp_path_, ec);
}

std::ostream& OutputFile::stream() {
  return kind_ == OutputKind::kStandardOutput ? std::cout : static_cast<std::ostream&>(file_);
}

void OutputFile::commit() {
  const core::SourceLocation where{path_, 0, 0, option_};
  if (kind_ == OutputKind::kStandardOutput) {
    // cout is synchronized with stdio: its characters sit in stdout's buffer until fflush, which
    // is where a full disk or a closed pipe shows.
    errno = 0;
    std::cout.flush();
    if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout))
      throw core::IoError(where, "writing to standard output failed: " + last_error());
    committed_ = published_ = true;
    return;
  }
  errno = 0;
  file_.flush();
  bool ok = static_cast<bool>(file_);
  file_.close();
  ok = ok && !file_.fail();
  if (!ok) throw core::IoError(where, "write failed: " + last_error());
  committed_ = true;
  if (kind_ == OutputKind::kDevice) published_ = true;
  else if (publish_ == Publish::OnCommit) publish();
}

void OutputFile::publish() {
  if (published_ || !committed_) return;
  std::error_code ec;
  std::filesystem::rename(temp_path_, path_, ec);
  if (ec)
    throw core::IoError({path_, 0, 0, option_}, "cannot move the finished file into place: " + ec.message());
  published_ = true;
}

}  // namespace servotwin::io
