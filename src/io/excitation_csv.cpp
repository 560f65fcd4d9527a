#include "servotwin/io/excitation_csv.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <istream>
#include <iterator>
#include <map>
#include <optional>
#include <ostream>
#include <sstream>

#include "csv_lines.hpp"
#include "number_format.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/signal_csv.hpp"

namespace servotwin::io {

namespace {

constexpr std::string_view kFormat = "servotwin.excitation/1";

using detail::trim_blanks;

/// A `# key: value` comment with where its value starts.
struct Entry {
  std::string value;
  std::size_t line = 0, column = 0;
};

/// The design comments before the header; `step` may repeat, the others not.
struct Preamble {
  std::map<std::string, Entry, std::less<>> keys;
  std::vector<Entry> steps;
};

Preamble read_preamble(const std::string& text, const std::string& source) {
  Preamble p;
  std::istringstream in(text);
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    const std::string_view body = trim_blanks(line);
    if (body.empty()) continue;
    if (body.front() != '#') break;  // the header: the design comes before it
    const std::string_view inner = trim_blanks(body.substr(1));
    const std::size_t colon = inner.find(':');
    if (colon == std::string_view::npos) continue;
    const std::string key(trim_blanks(inner.substr(0, colon)));
    const std::string_view value = trim_blanks(inner.substr(colon + 1));
    Entry entry{std::string(value), number, static_cast<std::size_t>(value.data() - line.data()) + 1};
    if (key == "step") p.steps.push_back(std::move(entry));
    else if (!p.keys.emplace(key, entry).second)
      throw core::InputError({source, number, 1, key}, "'# " + key + ":' appears twice");
  }
  return p;
}

class PreambleReader {
 public:
  PreambleReader(const Preamble& p, std::string source) : p_(p), source_(std::move(source)) {}

  const Entry& entry(std::string_view key) const {
    const auto it = p_.keys.find(key);
    if (it == p_.keys.end())
      throw core::InputError({source_, 0, 0, std::string(key)},
                             fmt::format("missing '# {}:' line (an excitation CSV carries its design before the "
                                         "header; write it with servotwin frf excitation)",
                                         key));
    return it->second;
  }
  bool has(std::string_view key) const { return p_.keys.find(key) != p_.keys.end(); }

  /// Blank-separated numbers of an entry.
  std::vector<double> numbers(const Entry& e, std::string_view key) const {
    std::vector<detail::Field> fields;
    detail::split_blank_separated(e.value, fields);
    std::vector<double> out;
    for (const auto& f : fields)
      out.push_back(detail::parse_number(detail::Field{f.text, e.column + f.column - 1},
                                         {source_, e.line, 0, std::string(key)}, key));
    return out;
  }
  double number(std::string_view key) const {
    const Entry& e = entry(key);
    const auto v = numbers(e, key);
    if (v.size() != 1) throw error(e, key, "expected one number, got \"" + e.value + "\"");
    return v.front();
  }
  std::size_t count(double v, const Entry& e, std::string_view key) const {
    if (!(v >= 0.0) || v != std::floor(v) || v > 1e12)
      throw error(e, key, fmt::format("expected a whole number >= 0, got {}", v));
    return static_cast<std::size_t>(v);
  }
  std::size_t whole(std::string_view key) const { return count(number(key), entry(key), key); }
  core::InputError error(const Entry& e, std::string_view key, const std::string& message) const {
    return core::InputError({source_, e.line, e.column, std::string(key)}, message);
  }

 private:
  const Preamble& p_;
  std::string source_;
};

frf::ExcitationType type_of(const PreambleReader& r) {
  const Entry& e = r.entry("type");
  if (e.value == "multisine") return frf::ExcitationType::kMultisine;
  if (e.value == "chirp") return frf::ExcitationType::kChirp;
  if (e.value == "sine-steps") return frf::ExcitationType::kSineSteps;
  throw r.error(e, "type", "unknown excitation type '" + e.value + "', expected multisine, chirp or sine-steps");
}

void read_periodic(const PreambleReader& r, frf::Excitation& e) {
  e.period_samples = r.whole("period_samples");
  e.periods = r.whole("periods");
  if (e.period_samples < 2 || e.periods < 1)
    throw r.error(r.entry("period_samples"), "period_samples", "expected at least 2 samples and 1 period");
  const Entry& lines = r.entry("lines");
  for (double v : r.numbers(lines, "lines")) {
    const std::size_t k = r.count(v, lines, "lines");
    if (k == 0 || 2 * k >= e.period_samples)
      throw r.error(lines, "lines", fmt::format("line {} is not between 1 and below half the period ({} samples)", k,
                                                e.period_samples));
    if (!e.lines.empty() && k <= e.lines.back()) throw r.error(lines, "lines", "lines must rise");
    e.lines.push_back(k);
  }
  // A single chirp is read by H1 and needs no lines; a periodic sequence does.
  if (e.lines.empty() && !(e.type == frf::ExcitationType::kChirp && e.periods == 1))
    throw r.error(lines, "lines", "no lines");
}

void read_steps(const Preamble& p, const PreambleReader& r, frf::Excitation& e) {
  for (const Entry& s : p.steps) {
    const auto v = r.numbers(s, "step");
    if (v.size() != 5) throw r.error(s, "step", "expected: freq_hz begin settle measure cycles");
    frf::SineStep step{v[0], r.count(v[1], s, "step"), r.count(v[2], s, "step"), r.count(v[3], s, "step"),
                       r.count(v[4], s, "step")};
    if (!(step.freq_hz > 0.0) || step.cycles == 0 || 2 * step.cycles >= step.measure_samples)
      throw r.error(s, "step", "expected a frequency > 0 and 1 <= cycles < measure/2");
    if (std::abs(step.freq_hz * static_cast<double>(step.measure_samples) * e.ts - static_cast<double>(step.cycles)) >
        1e-6 * static_cast<double>(step.cycles))
      throw r.error(s, "step", "freq_hz is not cycles / (measure * ts)");
    if (!e.steps.empty() && step.begin < e.steps.back().begin + e.steps.back().settle_samples +
                                             e.steps.back().measure_samples)
      throw r.error(s, "step", "steps must follow one another");
    e.steps.push_back(step);
  }
  if (e.steps.empty()) throw r.error(r.entry("type"), "step", "a sine-steps excitation needs '# step:' lines");
}

}  // namespace

void write_excitation_csv(std::ostream& out, const frf::Excitation& e, const std::vector<std::string>& comments) {
  fmt::memory_buffer b;
  auto to = std::back_inserter(b);
  fmt::format_to(to, "# format: {}\n# type: {}\n# ts: {}\n# range_hz: {} {}\n# amplitude: {}\n# crest_factor: {:.4f}\n",
                 kFormat, frf::excitation_type_name(e.type), e.ts, e.f_begin_hz, e.f_end_hz, e.amplitude,
                 e.crest_factor);
  if (e.type != frf::ExcitationType::kSineSteps) {
    fmt::format_to(to, "# period_samples: {}\n# periods: {}\n# lines:", e.period_samples, e.periods);
    for (std::size_t k : e.lines) fmt::format_to(to, " {}", k);
    fmt::format_to(to, "\n");
  }
  for (const auto& s : e.steps)
    fmt::format_to(to, "# step: {} {} {} {} {}\n", s.freq_hz, s.begin, s.settle_samples, s.measure_samples, s.cycles);
  for (const auto& c : comments) fmt::format_to(to, "# {}\n", c);
  fmt::format_to(to, "t,u\n");
  const int decimals = detail::time_decimals(0.0, e.ts);
  for (std::size_t i = 0; i < e.samples.size(); ++i) {
    detail::append_time(b, static_cast<double>(i) * e.ts, decimals);
    fmt::format_to(to, ",{}\n", e.samples[i]);
    if (b.size() > (1u << 16)) detail::write_out(b, out);
  }
  detail::write_out(b, out);
}

frf::Excitation read_excitation_csv(std::istream& in, std::string_view source_name) {
  const std::string source(source_name);
  std::ostringstream whole;
  whole << in.rdbuf();
  const std::string text = whole.str();
  const Preamble preamble = read_preamble(text, source);
  const PreambleReader r(preamble, source);
  const Entry& format = r.entry("format");
  if (format.value != kFormat)
    throw r.error(format, "format",
                  "not an excitation file: format '" + format.value + "', expected '" + std::string(kFormat) + "'");
  frf::Excitation e;
  e.type = type_of(r);
  e.ts = r.number("ts");
  if (!(e.ts > 0.0)) throw r.error(r.entry("ts"), "ts", "expected a sample period > 0 s");
  const Entry& range = r.entry("range_hz");
  const auto hz = r.numbers(range, "range_hz");
  if (hz.size() != 2 || !(hz[0] > 0.0 && hz[1] > hz[0])) throw r.error(range, "range_hz", "expected BEGIN END, 0 < BEGIN < END");
  e.f_begin_hz = hz[0];
  e.f_end_hz = hz[1];
  if (e.type == frf::ExcitationType::kSineSteps) read_steps(preamble, r, e);
  else read_periodic(r, e);

  SignalReadOptions options;
  options.columns = {"u"};
  options.fs = 1.0 / e.ts;
  std::istringstream body(text);
  SignalTable table = read_signal_csv(body, source, options);
  e.samples = std::move(table.columns.front());
  const std::size_t expected = e.type == frf::ExcitationType::kSineSteps
                                   ? e.steps.back().begin + e.steps.back().settle_samples + e.steps.back().measure_samples
                                   : e.period_samples * e.periods;
  if (e.samples.size() != expected)
    throw core::InputError({source, 0, 0, "u"}, fmt::format("{} samples, but the design in the comments makes {}",
                                                            e.samples.size(), expected));
  e.crest_factor = frf::crest_factor(e.samples);
  for (double v : e.samples) e.amplitude = std::max(e.amplitude, std::abs(v));
  return e;
}

frf::Excitation read_excitation_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError({path, 0, 0, ""}, "cannot open the file for reading");
  return read_excitation_csv(in, path);
}

}  // namespace servotwin::io
