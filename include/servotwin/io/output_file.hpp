#pragma once
/// \file
/// Output files that appear whole or not at all: a regular file's data goes to a temporary file
/// beside the target and is renamed over it once complete, so an error midway leaves nothing
/// behind. Standard output ("-" or /dev/stdout) and devices (/dev/null, a FIFO) are written
/// directly. Every write, flush and close is checked: a failure is a core::IoError.

#include <fstream>
#include <string>

namespace servotwin::io {

/// Whether an existing regular file may be replaced.
enum class Overwrite { Refuse, Allow };

/// When a complete regular file is moved onto its target: at commit(), or at publish() (a program
/// writing several files moves them into place together once all of them are complete; one rename
/// each, so not atomic across files).
enum class Publish { OnCommit, Deferred };

/// What an OutputFile writes to.
enum class OutputKind {
  kStandardOutput,  ///< "-" or /dev/stdout
  kDevice,          ///< an existing target that is not a regular file: written in place
  kRegularFile,     ///< through a temporary file beside the target
};

/// The kind of output `path` names, from what exists there now.
OutputKind output_kind(const std::string& path);

class OutputFile {
 public:
  /// Opens the output. `option` names the command-line option (or field) the path came from, for
  /// messages. Throws core::InputError when a regular target exists and `overwrite` is Refuse,
  /// when `path` is a directory, or when the temporary file cannot be created.
  OutputFile(std::string path, Overwrite overwrite, std::string option = "-o", Publish publish = Publish::OnCommit);
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  /// Removes the temporary file unless it was published.
  ~OutputFile();

  std::ostream& stream();
  /// Flushes and closes (core::IoError when anything written was lost); with Publish::OnCommit
  /// also moves a regular file into place.
  void commit();
  /// With Publish::Deferred: moves a committed regular file into place (core::IoError on
  /// failure). Does nothing for standard output, devices and already published files.
  void publish();
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  [[nodiscard]] const std::string& option() const noexcept { return option_; }
  [[nodiscard]] OutputKind kind() const noexcept { return kind_; }

 private:
  std::string path_;
  std::string option_;
  std::string temp_path_;
  std::ofstream file_;
  OutputKind kind_;
  Publish publish_;
  bool committed_ = false;
  bool published_ = false;
};

}  // namespace servotwin::io
