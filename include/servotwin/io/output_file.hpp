#pragma once
/// \file
/// Output files that appear whole or not at all: data goes to a temporary file beside the target
/// and is renamed over it on commit(), so an error midway leaves nothing behind.

#include <fstream>
#include <string>

namespace servotwin::io {

/// Whether an existing file may be replaced.
enum class Overwrite { Refuse, Allow };

class OutputFile {
 public:
  /// Opens a temporary file next to `path` ("-" = standard output, written directly).
  /// Throws core::InputError when `path` exists and `overwrite` is Refuse, or when the directory
  /// is not writable.
  OutputFile(std::string path, Overwrite overwrite);
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  /// Removes the temporary file unless committed.
  ~OutputFile();

  std::ostream& stream();
  /// Flushes and renames the temporary file onto the target (core::InputError on failure).
  void commit();
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
  std::string temp_path_;
  std::ofstream file_;
  bool to_stdout_ = false;
  bool committed_ = false;
};

}  // namespace servotwin::io
