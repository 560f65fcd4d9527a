#include "trace_table.hpp"

#include <charconv>
#include <cstring>
#include <cmath>
#include <fmt/format.h>

namespace servotwin::io::detail {

namespace {

std::string_view trimmed(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

constexpr std::string_view kHalscopePeriod = "# Sampling period is ";

}  // namespace

TraceTable::TraceTable(std::istream& in, const std::string& source, const CaptureReadOptions& options)
    : in_(in), source_(source), options_(options) {
  switch (options.format) {
    case TraceFormat::Halsampler:
      // No header: the names were given (halsampler writes values only).
      if (options.columns.empty())
        throw core::InputError({source, 0, 0, "--columns"},
                               "a halsampler file has no column names: give them with --columns x_cmd,x_act,... (one per "
                               "sampler pin, in pin order) or read them from the HAL file with --hal");
      for (std::size_t i = 0; i < options.columns.size(); ++i) header_.push_back(Field{options.columns[i], i + 1});
      return;
    case TraceFormat::Halscope: delimiter_ = ';'; break;
    case TraceFormat::Csv: delimiter_ = options.delimiter; break;
  }
  const std::string& prefix = options.format == TraceFormat::Halscope ? std::string("#") : options.comment_prefix;
  while (read_line()) {
    if (line_number_ == 1 && line_.substr(0, 3) == "\xEF\xBB\xBF") line_.remove_prefix(3);
    if (is_skippable_line(line_, prefix)) {
      if (options.format == TraceFormat::Halscope) read_halscope_period(line_, line_number_);
      continue;
    }
    header_line_ = line_number_;
    split_csv_line(line_, raw_, delimiter_);
    if (options.format == TraceFormat::Csv)
      check_header_delimiter(raw_, delimiter_, {source, header_line_, 0, ""}, "--delimiter");
    // The names must outlive the line buffer: keep a copy.
    names_.reserve(raw_.size());
    for (const Field& f : raw_) names_.emplace_back(f.text);
    for (std::size_t i = 0; i < raw_.size(); ++i) header_.push_back(Field{names_[i], raw_[i].column});
    if (options.format == TraceFormat::Halscope && !period_ && !options.ts)
      throw core::InputError({source, header_line_, 0, ""},
                             "no '# Sampling period is <n> ns' line before the channel names: is this a halscope log? "
                             "(give the period with --ts)");
    return;
  }
  throw core::InputError({source, line_number_, 0, ""}, "empty file: expected a header row with column names");
}

bool TraceTable::read_line() {
  while (true) {
    const char* start = buffer_.data() + begin_;
    if (const void* end = std::memchr(start, '\n', filled_ - begin_)) {
      const auto length = static_cast<std::size_t>(static_cast<const char*>(end) - start);
      line_ = std::string_view(start, length);
      begin_ += length + 1;
      consumed_ += length + 1;
      ++line_number_;
      line_complete_ = true;
      return true;
    }
    if (end_of_input_) {
      if (begin_ == filled_) return false;
      line_ = std::string_view(start, filled_ - begin_);  // the last line, without a line break
      consumed_ += filled_ - begin_;
      begin_ = filled_;
      ++line_number_;
      line_complete_ = false;
      return true;
    }
    // Keep the started line, make room (a line longer than the buffer doubles it) and read on.
    const std::size_t kept = filled_ - begin_;
    if (kept > 0 && begin_ > 0) std::memmove(buffer_.data(), start, kept);
    begin_ = 0;
    filled_ = kept;
    if (buffer_.empty()) buffer_.resize(kFirstBlock);
    else if (buffer_.size() < kBlock) buffer_.resize(kBlock);
    else if (filled_ == buffer_.size()) buffer_.resize(2 * buffer_.size());
    in_.read(buffer_.data() + filled_, static_cast<std::streamsize>(buffer_.size() - filled_));
    filled_ += static_cast<std::size_t>(in_.gcount());
    if (!in_) end_of_input_ = true;
  }
}

void TraceTable::read_halscope_period(std::string_view line, std::size_t number) {
  const std::string_view text = trimmed(line);
  const std::string_view lead = kHalscopePeriod;
  if (text.substr(0, lead.size()) != lead) return;
  std::string_view rest = text.substr(lead.size());
  long long ns = 0;
  const auto r = std::from_chars(rest.data(), rest.data() + rest.size(), ns);
  if (r.ec != std::errc{} || trimmed(std::string_view(r.ptr, static_cast<std::size_t>(rest.data() + rest.size() - r.ptr))) != "ns" ||
      ns <= 0)
    throw core::InputError({source_, number, 0, ""}, "expected '# Sampling period is <n> ns' with n > 0, found '" +
                                                         std::string(text.substr(0, 60)) + "'");
  period_ = static_cast<double>(ns) * 1e-9;
}

bool TraceTable::next(std::vector<Field>& fields) {
  if (options_.format == TraceFormat::Halsampler) return next_halsampler(fields);
  const std::string_view prefix = options_.format == TraceFormat::Halscope ? std::string_view("#") : options_.comment_prefix;
  while (read_line()) {
    if (is_skippable_line(line_, prefix)) continue;
    split_csv_line(line_, fields, delimiter_);
    if (fields.size() != header_.size())
      throw core::InputError({source_, line_number_, 0, ""}, "expected " + std::to_string(header_.size()) +
                                                                 " fields as in the header, found " +
                                                                 std::to_string(fields.size()));
    ++rows_;
    return true;
  }
  return false;
}

void TraceTable::check_not_a_counter() {
  // As many values as names, but the first counts 0, 1, 2, ...: halsampler -t's sample number
  // taken for a pin (one name too many), which would shift every column.
  if (rows_ >= 3 || counting_ == false) return;
  const Field& f = raw_.front();
  long long value = 0;
  const auto r = std::from_chars(f.text.data(), f.text.data() + f.text.size(), value);
  const bool integer = r.ec == std::errc{} && r.ptr == f.text.data() + f.text.size();
  counting_ = integer && (rows_ == 0 || value == counter_ + 1);
  counter_ = value;
  if (*counting_ && rows_ == 2)
    throw core::InputError({source_, line_number_, f.column, header_.front().text.empty() ? "" : std::string(header_.front().text)},
                           "the first column counts 1 by 1 like halsampler -t's sample number, which is not a pin: "
                           "name one column fewer (the names are for the pins only)");
}

bool TraceTable::next_halsampler(std::vector<Field>& fields) {
  const std::size_t named = header_.size();
  while (read_line()) {
    if (is_skippable_line(line_, options_.comment_prefix)) continue;
    if (trimmed(line_) == "overrun") {
      // sampler_usr.c prints it when the first sample it reads is not the next of its FIFO's
      // count: before the first row, samples were taken before this halsampler started reading.
      if (rows_ == 0) continue;
      throw core::InputError({source_, line_number_, 0, ""},
                             "'overrun': halsampler lost samples here, the trace has a gap; record again with a deeper "
                             "FIFO (loadrt sampler depth=...) or a faster reader");
    }
    split_blank_separated(line_, raw_);
    if (!numbered_) {
      if (raw_.size() == named || raw_.size() == named + 1) numbered_ = raw_.size() == named + 1;
    }
    const std::size_t expected = named + (numbered_.value_or(false) ? 1 : 0);
    if (raw_.size() != expected) {
      if (!line_complete_ && raw_.size() < expected) return false;  // the last line, cut short
      if (raw_.size() < named)
        throw core::InputError({source_, line_number_, 0, ""},
                               fmt::format("{} values on the line but {} columns named (--columns or the HAL file's "
                                           "sampler pins): the file has fewer columns than pins",
                                           raw_.size(), named));
      throw core::InputError({source_, line_number_, 0, ""},
                             fmt::format("{} values on the line, expected {} ({} named columns{})", raw_.size(), expected,
                                         named, numbered_.value_or(false) ? " and the sample number" : ""));
    }
    std::size_t first = 0;
    if (!*numbered_) check_not_a_counter();
    if (*numbered_) {
      const Field& n = raw_.front();
      long long value = 0;
      const auto r = std::from_chars(n.text.data(), n.text.data() + n.text.size(), value);
      if (r.ec != std::errc{} || r.ptr != n.text.data() + n.text.size())
        throw core::InputError({source_, line_number_, n.column, "sample"},
                               "expected halsampler's sample number (an integer), found '" + std::string(n.text.substr(0, 40)) + "'");
      // 32-bit counter; LinuxCNC 2.9 prints it signed, so 2^31 follows as -2^31.
      const auto number = static_cast<std::uint32_t>(value);
      if (rows_ > 0 && number != static_cast<std::uint32_t>(last_number_ + 1U)) {
        throw core::InputError({source_, line_number_, n.column, "sample"},
                               fmt::format("sample number jumps from {} to {}: {} samples lost, the trace has a gap "
                                           "(halsampler overrun or a restarted sampler)",
                                           last_number_, number, static_cast<std::uint32_t>(number - last_number_ - 1U)));
      }
      last_number_ = number;
      first = 1;
    }
    fields.assign(raw_.begin() + static_cast<std::ptrdiff_t>(first), raw_.end());
    ++rows_;
    return true;
  }
  return false;
}

}  // namespace servotwin::io::detail
