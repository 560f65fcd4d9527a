// `servotwin frf`: frequency responses. `frf measure` runs the real-time identification block
// (swept sine + harmonic observer, dissertation ch. 5) against a simulated flexible plant;
// `frf estimate` computes a response offline from recorded input and output signals (H1 with
// Welch averaging, or the per-period multisine estimator). Both write the frequency-response CSV.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>
#include <utility>
#include <optional>
#include <string>
#include <vector>

#include "command.hpp"
#include "frf_excitation.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_recording.hpp"
#include "servotwin/frf/offline.hpp"
#include "servotwin/io/excitation_csv.hpp"
#include "servotwin/io/frf_csv.hpp"
#include "servotwin/io/controller_json.hpp"
#include "servotwin/io/plant_json.hpp"
#include "servotwin/io/signal_csv.hpp"
#include "servotwin/machine/flexible_presets.hpp"
#include "servotwin/vcnc/frf_experiment.hpp"

namespace servotwin::cli {

namespace {

struct EstimateArgs {
  std::string data;
  std::string input, response;
  std::vector<std::string> files_out;  // -o/--output; two of them are an old --output COL
  std::string excitation;      // the design the drive played (frf excitation)
  bool closed_loop = false;
  std::string reference;       // closed loop: the excited reference column
  std::string method = "h1";
  std::string file_out;
  std::string time_column;
  std::optional<double> fs;
  double max_jitter = 0.01;
  // h1
  std::size_t segment = 0;
  double overlap = 0.5;
  std::string window = "hann";
  double fmin = 0.0, fmax = std::numeric_limits<double>::infinity();
  // multisine
  std::size_t periods = 0, period = 0;
  std::optional<std::size_t> skip_periods;
  std::optional<double> threshold_db;
  std::string detrend = "auto";
};

frf::Detrend detrend_of(const std::string& text, frf::Detrend fallback) {
  if (text == "none") return frf::Detrend::kNone;
  if (text == "mean") return frf::Detrend::kMean;
  if (text == "linear") return frf::Detrend::kLinear;
  return fallback;
}

/// "skip_periods" -> "skip-periods": the library's field as the option the user typed.
std::string dashed(std::string field) {
  std::replace(field.begin(), field.end(), '_', '-');
  return field;
}

/// Estimator errors name an option or a signal; say which file and column they concern.
[[noreturn]] void rethrow_located(const core::InputError& e, const EstimateArgs& a) {
  const std::string& field = e.where().field;
  std::string where = field == "input"       ? a.input
                      : field == "output"    ? a.response
                      : field == "reference" ? a.reference
                                             : "--" + dashed(field);
  throw core::InputError({a.data, 0, 0, where}, e.reason());
}

struct Estimated {
  core::FrequencyResponse response;
  std::vector<std::string> comments;
};

/// The period of a periodic input when neither --periods nor --period was given.
std::size_t detected_period(const std::vector<double>& x, const GlobalOptions& global) {
  const frf::PeriodDetection d = frf::detect_period(x);
  if (d.period_samples == 0)
    throw core::InputError(core::at_field("period"),
                           "no period found in the input (its autocorrelation stays below 0.8 at every lag up to half "
                           "the record); give --periods or --period, or use --method h1");
  progress(global, "multisine: detected a period of {} samples (autocorrelation {:.4f})", d.period_samples,
           d.correlation);
  return d.period_samples;
}

Estimated estimate(const EstimateArgs& a, const io::SignalTable& table, const GlobalOptions& global) {
  const std::vector<double>& x = table.column(a.input);
  const std::vector<double>& y = table.column(a.response);
  const std::vector<double>* r = a.closed_loop ? &table.column(a.reference) : nullptr;
  Estimated out;
  out.comments.push_back("source: " + a.data + ", input: " + a.input + ", output: " + a.response +
                         (r ? ", reference: " + a.reference + " (closed loop, indirect method)" : std::string()));
  try {
    if (a.method == "h1") {
      frf::WelchOptions o;
      o.segment_length = a.segment;
      o.overlap = a.overlap;
      o.window = a.window == "rect" ? frf::Window::kRectangular : frf::Window::kHann;
      o.detrend = detrend_of(a.detrend, frf::Detrend::kMean);
      o.min_freq_hz = a.fmin;
      o.max_freq_hz = a.fmax;
      out.response = r ? frf::estimate_closed_loop_h1(*r, x, y, table.ts, o) : frf::estimate_h1(x, y, table.ts, o);
      const frf::WelchLayout s = frf::welch_layout(x.size(), table.ts, o);
      out.comments.push_back(fmt::format("method: {} (Welch), segment {} samples, {} window, overlap {}, {} segments "
                                         "({:.1f} effective averages), df {} Hz",
                                         r ? "closed loop, indirect S_ry/S_ru" : "h1", s.segment_length, a.window, a.overlap, s.segments, s.effective_averages,
                                         s.df_hz));
      progress(global, "H1: {} segments of {} samples ({:.1f} effective averages), df {} Hz", s.segments,
               s.segment_length, s.effective_averages, s.df_hz);
    } else {
      frf::MultisineOptions o;
      o.periods = a.periods;
      o.period_samples = a.period;
      o.skip_periods = a.skip_periods.value_or(0);
      if (o.periods == 0 && o.period_samples == 0) o.period_samples = detected_period(r ? *r : x, global);
      o.detrend = detrend_of(a.detrend, frf::Detrend::kLinear);
      o.excitation_threshold_db = a.threshold_db;
      frf::MultisineEstimate e =
          r ? frf::estimate_closed_loop_multisine(*r, x, y, table.ts, o) : frf::estimate_multisine(x, y, table.ts, o);
      out.comments.push_back(fmt::format("method: multisine (per-period DFT), period {} samples, {} periods used, {} "
                                         "skipped, {} excited lines, df {} Hz",
                                         e.period_samples, e.periods_used, e.periods_skipped, e.lines.size(), e.df_hz));
      out.comments.push_back("note: coherence_or_thd is the coherence equivalent |G|^2/(|G|^2 + P*std^2)");
      progress(global, "multisine: period {} samples, {} periods used ({} skipped, {} trailing samples dropped), {} "
               "excited lines", e.period_samples, e.periods_used, e.periods_skipped, e.samples_dropped, e.lines.size());
      out.response = std::move(e.response);
    }
  } catch (const core::InputError& e) {
    rethrow_located(e, a);
  }
  return out;
}

/// --excitation: align the recording with the played design and estimate as its type allows.
Estimated estimate_recorded(const EstimateArgs& a, const io::SignalTable& table, const GlobalOptions& global) {
  const frf::Excitation excitation = io::read_excitation_file(a.excitation);
  if (std::abs(excitation.ts - table.ts) > 1e-6 * excitation.ts)
    throw core::InputError({a.data, 0, 0, "--excitation"},
                           fmt::format("sampled every {} s, but {} was designed for {} s: record at the period the "
                                       "drive played it",
                                       table.ts, a.excitation, excitation.ts));
  frf::RecordedOptions options;
  options.skip_periods = a.skip_periods.value_or(1);
  frf::RecordedEstimate r;
  try {
    r = frf::estimate_recorded(excitation, table.column(a.input), table.column(a.response), options);
  } catch (const core::InputError& e) {
    rethrow_located(e, a);
  }
  const frf::Alignment& al = r.alignment;
  progress(global, "{} found at sample {} (t = {} s), gain {:.4g}, correlation {:.4f}",
           frf::excitation_type_name(excitation.type), al.offset, static_cast<double>(al.offset) * table.ts + table.t0,
           al.gain, al.correlation);
  progress(global, "{}", r.method);
  Estimated out;
  out.comments.push_back("source: " + a.data + ", input: " + a.input + ", output: " + a.response);
  out.comments.push_back(fmt::format("excitation: {} ({}), found at sample {}, gain {:.6g}, correlation {:.6f}",
                                     a.excitation, frf::excitation_type_name(excitation.type), al.offset, al.gain,
                                     al.correlation));
  out.comments.push_back("method: " + r.method);
  out.response = std::move(r.response);
  return out;
}

void print_summary(const core::FrequencyResponse& r) {
  std::vector<double> quality;
  for (const auto& p : r.points) quality.push_back(p.quality);
  std::sort(quality.begin(), quality.end());
  // Coherence: the worst is the lowest; THD: the highest.
  const bool thd = r.quality_kind == core::QualityKind::kThd;
  fmt::print("frf: {} points, {} ... {} Hz, {} median {:.4f}, {} {:.4f}, duration {} s\n", r.size(),
             r.points.front().freq_hz, r.points.back().freq_hz, thd ? "THD" : "coherence", quality[quality.size() / 2],
             thd ? "max" : "min", thd ? quality.back() : quality.front(), r.duration_s.value_or(0.0));
}

int run_estimate(const EstimateArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  io::SignalReadOptions reading;
  if (a.closed_loop && a.reference.empty())
    throw core::InputError(core::at_field("--reference"),
                           "a closed-loop estimate needs the excited reference column: the plant is P = S_ry/S_ru, "
                           "and without r the noise fed back through the loop biases it");
  reading.columns = {a.input};
  for (const std::string* c : {&a.response, &a.reference})
    if (!c->empty() && std::find(reading.columns.begin(), reading.columns.end(), *c) == reading.columns.end())
      reading.columns.push_back(*c);
  reading.time_column = a.time_column;
  reading.fs = a.fs;
  reading.max_jitter = a.max_jitter;
  const io::SignalTable table = io::read_signal_file(a.data, reading);
  io::require_varying(table, a.closed_loop ? a.reference : a.input);
  progress(global, "read {}: {} samples at {} Hz{} in {:.1f} ms", a.data, table.size(), 1.0 / table.ts,
           table.time_column.empty() ? " (--fs)" : " (from " + table.time_column + ")", elapsed_ms(start));

  const Estimated estimated = a.excitation.empty() ? estimate(a, table, global) : estimate_recorded(a, table, global);
  auto out = open_output(a.file_out, global);
  io::write_frf_csv(out->stream(), estimated.response, estimated.comments);
  out->commit();
  if (a.file_out != "-") print_summary(estimated.response);
  progress(global, "wrote {} ({} points) in {:.1f} ms", out->path(), estimated.response.size(), elapsed_ms(start));
  return kSuccess;
}

void add_estimate(CLI::App& frf, Action& selected) {
  auto a = std::make_shared<EstimateArgs>();
  CLI::App* cmd = frf.add_subcommand("estimate", "Estimate a frequency response offline from recorded input and output");
  cmd->add_option("data", a->data,
                  "Recorded CSV with a header: a time column (t or time in s, or t_/time_ + s|ms|us|ns, e.g. time_us) "
                  "or --fs, and the signal columns")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--input", a->input, "Column of the excitation (input)")->required();
  // Required, checked in the callback so that an old invocation (--output COL) is told about it.
  cmd->add_option("--response", a->response, "Column of the response (output); required");
  auto* closed = cmd->add_flag("--closed-loop", a->closed_loop,
                               "The record was taken inside a closed loop whose reference was excited: estimate the "
                               "plant (input -> response) by the indirect method P = S_ry/S_ru (needs --reference)");
  cmd->add_option("--reference", a->reference, "Closed loop: the column of the excited reference")->needs(closed);
  CLI::Option* excitation = cmd->add_option("--excitation", a->excitation,
                  "Excitation CSV the drive played (servotwin frf excitation): the recording is aligned with it and "
                  "estimated as its type allows (per-period DFT, H1 of a single sweep, or one line per sine step)")
      ->check(CLI::ExistingFile);
  // -o/--output names the file; before, --output named the response column, so an invocation with
  // both is an old one: refused with a pointer to --response rather than read as two files.
  cmd->add_option("-o,--output", a->files_out, "Frequency-response CSV to write ('-' = stdout)")
      ->required()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--method", a->method,
                  "h1: Welch-averaged Sxy/Sxx for broadband data (noise, chirp, PRBS); multisine: per-period DFT "
                  "averages for periodic excitation")
      ->check(CLI::IsMember({"h1", "multisine"}))
      ->capture_default_str();
  cmd->add_option("--fs", a->fs, "Sample rate [Hz] for files without a time column (checked against it otherwise)")
      ->check(positive_number());
  cmd->add_option("--time-column", a->time_column, "Time column (default: the first named t, time, t_<unit>, time_<unit>)");
  cmd->add_option("--max-jitter", a->max_jitter, "Largest accepted time-stamp deviation from the uniform grid, "
                                                 "relative to the sample period")
      ->capture_default_str();
  cmd->add_option("--segment", a->segment,
                  "h1: samples per segment (default: the largest power of two giving >= 8 segments)");
  cmd->add_option("--overlap", a->overlap, "h1: segment overlap fraction in [0, 1)")->capture_default_str();
  cmd->add_option("--window", a->window, "h1: window of each segment: hann or rect")
      ->check(CLI::IsMember({"hann", "rect"}))
      ->capture_default_str();
  cmd->add_option("--fmin-hz", a->fmin, "h1: lowest frequency written [Hz]");
  cmd->add_option("--fmax-hz", a->fmax, "h1: highest frequency written [Hz]");
  add_old_spelling(*cmd, "--fmin", a->fmin, "--fmin-hz");
  add_old_spelling(*cmd, "--fmax", a->fmax, "--fmax-hz");
  cmd->add_option("--periods", a->periods, "multisine: whole periods in the record (the period is the record / N)");
  cmd->add_option("--period", a->period, "multisine: samples per period (instead of or with --periods)");
  cmd->add_option("--skip-periods", a->skip_periods,
                  "multisine: leading periods dropped as transient (default 0; 1 with --excitation)");
  cmd->add_option("--excitation-threshold-db", a->threshold_db,
                  "multisine: excited lines are within this many dB (< 0) of the strongest input line (default: the "
                  "largest gap in the input line powers)");
  cmd->add_option("--detrend", a->detrend,
                  "Removed before the DFT: none, mean, linear (default: mean per segment for h1, the drift line "
                  "through the period means for multisine)")
      ->check(CLI::IsMember({"auto", "none", "mean", "linear"}))
      ->capture_default_str();
  // The design decides the estimator: options that choose or tune another one would be ignored,
  // and --closed-loop would be the biased open-loop estimate of a single sweep.
  for (const char* name : {"--closed-loop", "--method", "--segment", "--overlap", "--window", "--periods", "--period",
                           "--excitation-threshold-db"})
    excitation->excludes(cmd->get_option(name));
  set_examples(*cmd,
               "  servotwin frf estimate MultisineTypeA.csv --input iq_adx --response theta_mx --method multisine "
               "--periods 20 --skip-periods 1 -o frf.csv\n"
               "  servotwin frf estimate run.csv --input u --response y --method h1 --segment 4096 -o frf.csv\n"
               "  servotwin frf estimate log.csv --fs 8000 --input torque --response speed -o frf.csv --force\n");
  cmd->callback([a, &selected] {
    if (a->files_out.size() > 1)
      throw CLI::ValidationError("--output", "--output no longer names the response column: use --response COL "
                                             "(-o/--output names the file written)");
    if (a->response.empty()) throw CLI::RequiredError("--response");
    a->file_out = a->files_out.front();
    selected = [a](const GlobalOptions& g) { return run_estimate(*a, g); };
  });
}


// ---- frf measure ---------------------------------------------------------------------------

struct MeasureArgs {
  std::string plant;
  std::string range = "1:500";
  std::size_t points = 30;
  std::optional<double> amplitude, max_amplitude, output_limit;
  double sweep_time = 0.0;
  double thd = 0.05;
  double max_time = 0.0;
  bool open_loop = false;
  std::string controller;  // closed loop: the velocity controller the block runs inside
  std::string out;
  std::string trace;
};

std::string state_name(frf::RfidState state) {
  switch (state) {
    case frf::RfidState::kIdle: return "idle";
    case frf::RfidState::kSweep: return "sweep";
    case frf::RfidState::kSettle: return "settle";
    case frf::RfidState::kRampOut: return "ramp-out";
    case frf::RfidState::kDone: return "done";
    case frf::RfidState::kAborted: return "aborted";
  }
  return "?";
}

void write_trace(std::ostream& out, const vcnc::FrfExperiment& e) {
  out << "t,mv,pv,f_hz,amplitude,thd,state\n";
  for (const auto& s : e.trace)
    out << fmt::format("{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{}\n", s.t, s.mv, s.pv, s.f_hz, s.amplitude, s.thd,
                       state_name(s.state));
}

void print_measurement(const std::string& plant_name, const vcnc::FrfExperiment& e) {
  fmt::print("frf measure on {}: {}, {} points ({} detected at resonances/antiresonances) in {:.2f} s of experiment\n",
             plant_name, vcnc::outcome_text(e), e.points.size(),
             std::count_if(e.points.begin(), e.points.end(),
                           [](const frf::MeasuredPoint& p) { return p.kind != frf::PointKind::kListed; }),
             e.response.duration_s.value_or(0.0));
  for (const auto& p : e.points) {
    if (p.kind == frf::PointKind::kListed) continue;
    fmt::print("  {} near {:.3f} Hz: |P| = {:.4g}, THD {:.3f}\n", vcnc::point_kind_name(p.kind),
               p.omega / (2.0 * std::numbers::pi), std::abs(p.response), p.thd);
  }
  const auto unsettled = std::count_if(e.points.begin(), e.points.end(), [](const frf::MeasuredPoint& p) { return !p.settled; });
  if (unsettled > 0) fmt::print("  {} {} latched at the settling-time limit without converging\n", unsettled,
                              plural(unsettled, "point", "points"));
  for (const core::FrequencyPoint& p : e.response.points)
    if (!p.valid) fmt::print("  invalid at {:.4g} Hz, left out of fits: {}\n", p.freq_hz, p.note);
}

int run_measure(const MeasureArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const machine::PlantConfig config = io::load_plant(a.plant);
  machine::FlexiblePlant plant(config);
  vcnc::FrfExperimentSettings settings;
  std::tie(settings.f_begin_hz, settings.f_end_hz) = parse_range_hz(a.range, "--range-hz");
  settings.points = a.points;
  settings.amplitude = a.amplitude;
  settings.max_amplitude = a.max_amplitude;
  settings.output_limit = a.output_limit;
  settings.sweep_time_s = a.sweep_time;
  settings.thd_threshold = a.thd;
  settings.max_time_s = a.max_time;
  settings.hold_dc = !a.open_loop;
  const bool closed = !a.controller.empty();
  std::optional<core::DiscreteStateSpace> controller;
  if (closed) {
    const io::LoadedController loaded = io::load_controller(a.controller);
    try {
      controller = tuning::discretize_controller(loaded.controller, plant.ts());
    } catch (const core::InputError& e) {
      throw core::InputError({a.controller, 0, 0, e.where().field}, e.reason());
    }
  }
  const frf::RfidParameters parameters =
      closed ? vcnc::closed_loop_parameters(plant, settings) : vcnc::experiment_parameters(plant, settings);
  const double dc_gain = closed ? 0.0 : vcnc::dc_hold_gain(plant, settings);
  // Outputs are opened before the run, so an existing file stops the command before the work.
  auto out = open_output(a.out, global);
  auto trace_out = a.trace.empty() ? nullptr : open_output(a.trace, global, "--trace");
  progress(global, "{}: {} to {} Hz, {} listed points, start amplitude {:.4g}, limit {:.4g}, output range +-{:.4g}{}",
           config.name.empty() ? a.plant : config.name, settings.f_begin_hz, settings.f_end_hz, settings.points,
           parameters.initial_amplitude, parameters.max_amplitude, parameters.output_max,
           closed            ? ", inside the velocity loop of " + a.controller
           : dc_gain > 0.0   ? fmt::format(", semi-closed loop (gain {:.3g})", dc_gain)
                             : std::string(", open loop"));
  const auto report = [&](double t, std::size_t points, double f_hz) {
    if (t >= 1.0 && std::fmod(t, 5.0) < 1.0) progress(global, "  t = {:.0f} s: {} points, at {:.1f} Hz", t, points, f_hz);
  };
  vcnc::FrfExperiment e;
  if (closed) {
    try {
      e = vcnc::run_frf_experiment_closed_loop(plant, parameters, vcnc::time_limit(settings), *controller,
                                               trace_out != nullptr, report);
    } catch (const core::InputError& error) {
      throw core::InputError({a.controller, 0, 0, "controller"}, error.reason());
    }
  } else {
    e = vcnc::run_frf_experiment(plant, parameters, vcnc::time_limit(settings), trace_out != nullptr, dc_gain, report);
  }
  print_measurement(config.name.empty() ? a.plant : config.name, e);
  if (e.response.points.size() < 2)
    throw core::InputError(core::at_field(a.plant), "the experiment " + vcnc::outcome_text(e) + " with fewer than 2 points");
  std::vector<std::string> comments{
      "source: frf measure --plant " + a.plant,
      fmt::format("method: swept sine + harmonic observer (real-time block), {}, ts {} s", vcnc::outcome_text(e), plant.ts()),
      "note: the response is that of the sampled plant (zero-order hold included)"};
  if (closed)
    comments.push_back("closed loop: the block excited the velocity reference of " + a.controller +
                       "; P = T/(C_r + T C_y) from the measured T = y/reference and the controller's responses");
  io::write_frf_csv(out->stream(), e.response, comments);
  out->commit();
  if (trace_out) {
    write_trace(trace_out->stream(), e);
    trace_out->commit();
  }
  progress(global, "wrote {} ({} points) in {:.0f} ms", out->path(), e.response.size(), elapsed_ms(start));
  return e.final_state == frf::RfidState::kDone ? kSuccess : kBadInput;
}

void add_measure(CLI::App& frf, Action& selected) {
  auto a = std::make_shared<MeasureArgs>();
  std::string presets;
  for (const auto& name : machine::flexible_preset_names()) presets += (presets.empty() ? "" : ", ") + name;
  CLI::App* cmd = frf.add_subcommand(
      "measure", "Measure a frequency response with the real-time identification block on a simulated plant");
  cmd->add_option("--plant", a->plant, "Plant JSON (servotwin.plant/1) or preset: " + presets)->required();
  cmd->add_option("--range-hz", a->range, "Frequency range BEGIN:END [Hz]; END below fs/10")->capture_default_str();
  cmd->add_option("--points", a->points, "Listed measurement frequencies, logarithmically spaced (extra points are "
                                         "added at resonances and antiresonances)")
      ->capture_default_str();
  cmd->add_option("--amplitude", a->amplitude, "Initial excitation amplitude (default: 300 x the noise at the start)");
  cmd->add_option("--max-amplitude", a->max_amplitude, "Ceiling of the excitation amplitude (default: 100 x initial)");
  cmd->add_option("--output-limit", a->output_limit, "Allowed output range +-LIMIT; the block stops outside it");
  cmd->add_option("--sweep-time", a->sweep_time,
                  "Time the logarithmic sweep alone takes [s] (default: max(8 s, 8 periods of the first frequency))");
  cmd->add_option("--thd", a->thd, "THD threshold of the amplitude adaptation")->capture_default_str();
  cmd->add_option("--max-time", a->max_time,
                  "Stop the simulation after this much experiment time [s] (default: max(120 s, 200 periods of the "
                  "first frequency + 4 sweep times))");
  cmd->add_flag("--open-loop", a->open_loop, "No semi-closed loop on the DC estimate (velocity outputs)");
  cmd->add_option("--controller", a->controller,
                  "Run the block inside this velocity loop (servotwin.controller/1): it excites the reference, and "
                  "the plant follows from the measured closed loop and the controller (indirect method)")
      ->check(CLI::ExistingFile);
  add_output_file_option(*cmd, a->out, "Frequency-response CSV to write ('-' = stdout)")->required();
  cmd->add_option("--trace", a->trace, "Also write every sample (t, mv, pv, f_hz, amplitude, thd, state) as CSV");
  set_examples(*cmd,
               "  servotwin frf measure --plant motor-bench --range-hz 1:500 -o frf.csv\n"
               "  servotwin frf measure --plant my_axis.json --range-hz 2:300 --points 40 -o frf.csv --trace trace.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run_measure(*a, g); }; });
}

}  // namespace

void register_frf(CLI::App& app, Action& selected) {
  CLI::App* frf = app.add_subcommand("frf", "Frequency responses: measure one on a simulated plant, estimate one "
                                            "from recorded data, or write an excitation for a drive to play");
  frf->require_subcommand(1);
  add_measure(*frf, selected);
  add_estimate(*frf, selected);
  add_excitation(*frf, selected);
}

}  // namespace servotwin::cli
