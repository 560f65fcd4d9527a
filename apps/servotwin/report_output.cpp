#include "report_output.hpp"

namespace servotwin::cli {

void add_report_option(CLI::App& command, std::string& path) {
  command.add_option("--report", path,
                     "Write an interactive HTML report: one self-contained file that opens offline in a browser");
}

std::shared_ptr<io::OutputFile> open_report(const std::string& path, const GlobalOptions& global) {
  if (path.empty()) return nullptr;
  return open_output(path, global, "--report");
}

void write_report(const report::Document& doc, io::OutputFile& out, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  report::write_html(out.stream(), doc);
  const auto size = out.stream().tellp();
  out.commit();
  progress(global, "wrote report {} ({:.0f} kB, {} charts) in {:.1f} ms", out.path(),
           size >= 0 ? static_cast<double>(size) / 1000.0 : 0.0, report::chart_count(doc), elapsed_ms(start));
}

}  // namespace servotwin::cli
