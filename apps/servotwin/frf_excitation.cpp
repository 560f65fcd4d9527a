// `servotwin frf excitation`: the design of frf/excitation_design.hpp written as an excitation CSV
// (io/excitation_csv.hpp) that a drive's signal generator plays and `frf estimate --excitation`
// reads back.
#include "frf_excitation.hpp"

#include <chrono>
#include <map>
#include <optional>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_design.hpp"
#include "servotwin/io/excitation_csv.hpp"

namespace servotwin::cli {

namespace {

struct ExcitationArgs {
  std::string type = "multisine";
  std::string range = "1:500";
  double ts = 0.0;
  double duration = 0.0;
  double amplitude = 0.0;
  std::optional<double> limit;
  std::size_t periods = 0;
  std::string spacing = "linear";
  std::size_t lines_per_decade = 30;
  std::size_t steps = 0;
  double settle_fraction = 0.25;
  std::string out;
};

frf::ExcitationType excitation_type_of(const std::string& name) {
  if (name == "chirp") return frf::ExcitationType::kChirp;
  if (name == "sine-steps") return frf::ExcitationType::kSineSteps;
  return frf::ExcitationType::kMultisine;
}

/// The library names its fields; the user typed options.
[[noreturn]] void rethrow_excitation_error(const core::InputError& e) {
  rethrow_as_option(e, {{"f_begin_hz", "--range-hz"},
                        {"f_end_hz", "--range-hz"},
                        {"ts", "--ts"},
                        {"duration_s", "--duration"},
                        {"amplitude", "--amplitude"},
                        {"periods", "--periods"},
                        {"steps", "--steps"},
                        {"lines_per_decade", "--lines-per-decade"},
                        {"settle_fraction", "--settle-fraction"}});
  throw e;
}

frf::ExcitationRequest request_of(const ExcitationArgs& a) {
  frf::ExcitationRequest r;
  r.type = excitation_type_of(a.type);
  std::tie(r.f_begin_hz, r.f_end_hz) = parse_range_hz(a.range, "--range-hz");
  r.ts = a.ts;
  r.duration_s = a.duration;
  r.amplitude = a.amplitude;
  r.periods = a.periods;
  r.spacing = a.spacing == "log" ? frf::LineSpacing::kLogarithmic : frf::LineSpacing::kLinear;
  r.lines_per_decade = a.lines_per_decade;
  r.steps = a.steps;
  r.settle_fraction = a.settle_fraction;
  if (a.limit && !(a.amplitude <= *a.limit))
    throw core::InputError(core::at_field("--amplitude"),
                           fmt::format("the peak {} exceeds --limit {}: the drive would clip it", a.amplitude, *a.limit));
  return r;
}

void print_design(const frf::Excitation& e) {
  const double rms = e.crest_factor > 0.0 ? e.amplitude / e.crest_factor : 0.0;
  const double length_s = static_cast<double>(e.samples.size()) * e.ts;
  switch (e.type) {
    case frf::ExcitationType::kMultisine: {
      const double df = 1.0 / (static_cast<double>(e.period_samples) * e.ts);
      fmt::print("multisine: {} periods of {} samples ({} s each), {} lines {} ... {} Hz (line spacing {} Hz)\n",
                 e.periods, e.period_samples, static_cast<double>(e.period_samples) * e.ts, e.lines.size(),
                 static_cast<double>(e.lines.front()) * df, static_cast<double>(e.lines.back()) * df, df);
      fmt::print("  peak {}, rms {:.4g}, crest factor {:.3f} (Schroeder's phases alone: {:.3f})\n", e.amplitude, rms,
                 e.crest_factor, e.schroeder_crest_factor);
      break;
    }
    case frf::ExcitationType::kChirp:
      fmt::print("chirp: {} logarithmic {} of {} s, {} ... {} Hz\n", e.periods, plural(e.periods, "sweep", "sweeps"),
                 static_cast<double>(e.period_samples) * e.ts, e.f_begin_hz, e.f_end_hz);
      fmt::print("  peak {}, rms {:.4g}, crest factor {:.3f}\n", e.amplitude, rms, e.crest_factor);
      break;
    case frf::ExcitationType::kSineSteps: {
      const auto& s = e.steps.front();
      fmt::print("sine-steps: {} frequencies {:.4g} ... {:.4g} Hz, {:.4g} s each ({:.4g} s settling, then {:.4g} s "
                 "measured)\n",
                 e.steps.size(), s.freq_hz, e.steps.back().freq_hz,
                 static_cast<double>(s.settle_samples + s.measure_samples) * e.ts,
                 static_cast<double>(s.settle_samples) * e.ts, static_cast<double>(s.measure_samples) * e.ts);
      fmt::print("  peak {}, rms {:.4g}, crest factor {:.3f}\n", e.amplitude, rms, e.crest_factor);
      break;
    }
  }
  fmt::print("  {} samples, {:.6g} s at {:.6g} Hz\n", e.samples.size(), length_s, 1.0 / e.ts);
}

int run_excitation(const ExcitationArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  check_sample_period(a.ts);
  const frf::ExcitationRequest request = request_of(a);
  auto out = open_output(a.out, global);
  frf::Excitation e;
  try {
    e = frf::design_excitation(request);
  } catch (const core::InputError& error) {
    rethrow_excitation_error(error);
  }
  io::write_excitation_csv(out->stream(), e,
                           {"play u at ts from its first row; record u (as the drive applied it) and the response, "
                            "then: servotwin frf estimate REC.csv --input U --response Y --excitation THIS.csv"});
  out->commit();
  if (a.out != "-") print_design(e);
  progress(global, "wrote {} in {:.0f} ms", out->path(), elapsed_ms(start));
  return kSuccess;
}

}  // namespace

void add_excitation(CLI::App& frf, Action& selected) {
  auto a = std::make_shared<ExcitationArgs>();
  CLI::App* cmd = frf.add_subcommand("excitation", "Write an excitation for a drive's own signal generator "
                                                   "(multisine, chirp or sine steps)");
  cmd->add_option("--type", a->type,
                  "multisine: equal lines of a period, low crest factor, repeated (leakage-free); chirp: logarithmic "
                  "sweep; sine-steps: one settled sine per frequency")
      ->check(CLI::IsMember({"multisine", "chirp", "sine-steps"}))
      ->capture_default_str();
  cmd->add_option("--range-hz", a->range, "Excited range BEGIN:END [Hz], END below the Nyquist frequency of --ts")
      ->capture_default_str();
  cmd->add_option("--ts", a->ts, "The drive's sample period [s] at which it plays the sequence")->required();
  cmd->add_option("--duration", a->duration, "Length of the sequence [s]")->required();
  cmd->add_option("--amplitude", a->amplitude, "Peak value, in the units the drive plays (e.g. A or % of rated torque)")
      ->required();
  cmd->add_option("--limit", a->limit, "Largest value the drive accepts; a larger --amplitude is refused");
  cmd->add_option("--periods", a->periods,
                  "multisine, chirp: periods in the sequence (default: multisine as many as fit with a line spacing "
                  "of at most BEGIN; chirp 1)");
  cmd->add_option("--spacing", a->spacing, "multisine: lines linear (every line) or log (--lines-per-decade)")
      ->check(CLI::IsMember({"linear", "log"}))
      ->capture_default_str();
  cmd->add_option("--lines-per-decade", a->lines_per_decade, "multisine with --spacing log")->capture_default_str();
  cmd->add_option("--steps", a->steps, "sine-steps: number of frequencies (default: 10 per decade)");
  cmd->add_option("--settle-fraction", a->settle_fraction, "sine-steps: part of each step before it is measured")
      ->capture_default_str();
  add_output_file_option(*cmd, a->out, "Excitation CSV to write ('-' = stdout)")->required();
  set_examples(*cmd,
               "  servotwin frf excitation --type multisine --range-hz 1:500 --ts 0.001 --duration 30 --amplitude 2 "
               "-o excitation.csv\n"
               "  servotwin frf excitation --type chirp --range-hz 5:400 --ts 0.000125 --duration 10 --amplitude 0.5 "
               "-o chirp.csv\n"
               "  servotwin frf excitation --type sine-steps --range-hz 2:200 --ts 0.0005 --duration 60 --amplitude 1 "
               "-o steps.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run_excitation(*a, g); }; });
}

}  // namespace servotwin::cli
