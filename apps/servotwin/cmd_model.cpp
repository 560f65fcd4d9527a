// `servotwin model`: show an identified axis model and write its frequency responses.
#include <cmath>
#include <complex>
#include <numbers>

#include "command.hpp"
#include "model_summary.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/rapid_json.hpp"

namespace servotwin::cli {

namespace {


struct ModelArgs {
  std::string model;
  std::string frf;
  double fmin_hz = 0.1, fmax_hz = 0.0;
  std::size_t points = 400;
};

double db(std::complex<double> g) { return 20.0 * std::log10(std::abs(g)); }
double degrees(std::complex<double> g) { return std::arg(g) * 180.0 / std::numbers::pi; }

int run(const ModelArgs& a, const GlobalOptions& global) {
  const io::LoadedAxisModel loaded = io::load_axis_model(a.model);
  const rapid::AxisModel& m = loaded.model;
  const auto& c = m.coefficients();
  fmt::print("{}: axis {}, ts {} s{}{}\n", a.model, loaded.axis, m.ts(),
             loaded.method.empty() ? "" : ", identified with " + loaded.method,
             loaded.command_shift == 0 ? "" : fmt::format(", command shift {} samples", loaded.command_shift));
  fmt::print("  a1 = {:.6g}  a2 = {:.6g}  a3 = {:.6g}\n  b0 = {:.6g}  b1 = {:.6g}  b2 = {:.6g}\n  d0 = {:.6g}  d1 = {:.6g}\n",
             c.a1, c.a2, c.a3, c.b0, c.b1, c.b2, c.d0, c.d1);
  print_roots("poles", m.poles());
  print_roots("zeros", m.zeros());
  fmt::print("  {}; {}; tracking DC gain {:.6g}\n", m.is_stable() ? "stable" : "UNSTABLE", bandwidth_text(m),
             m.tracking().dc_gain());
  if (a.frf.empty()) return kSuccess;

  const double nyquist_hz = 0.5 / m.ts();
  const double fmax = a.fmax_hz > 0.0 ? a.fmax_hz : nyquist_hz;
  if (!(a.fmin_hz > 0.0 && fmax > a.fmin_hz))
    throw core::InputError({"", 0, 0, "--fmin-hz"}, fmt::format("need 0 < fmin < fmax, got {} and {}", a.fmin_hz, fmax));
  const std::vector<double> f = core::log_space(a.fmin_hz, fmax, a.points);
  std::vector<double> w(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) w[i] = kTwoPi * f[i];
  // The model explains x(k) by x_r(k + shift): its response to the command carries the shift.
  auto tracking = m.tracking().frequency_response(w);
  for (std::size_t i = 0; i < w.size(); ++i) tracking[i] *= std::polar(1.0, w[i] * loaded.command_shift * m.ts());
  const auto disturbance = m.disturbance().frequency_response(w);
  auto out = open_output(a.frf, global, "--frf");
  out->stream() << "freq_hz,tracking_re,tracking_im,tracking_mag_db,tracking_phase_deg,"
                   "disturbance_re,disturbance_im,disturbance_mag_db,disturbance_phase_deg\n";
  for (std::size_t i = 0; i < f.size(); ++i)
    out->stream() << fmt::format("{},{},{},{},{},{},{},{},{}\n", f[i], tracking[i].real(), tracking[i].imag(),
                                 db(tracking[i]), degrees(tracking[i]), disturbance[i].real(), disturbance[i].imag(),
                                 db(disturbance[i]), degrees(disturbance[i]));
  out->commit();
  progress(global, "wrote {} frequency points ({:.3g} .. {:.4g} Hz) to {}", f.size(), a.fmin_hz, fmax, a.frf);
  return kSuccess;
}

}  // namespace

void register_model(CLI::App& app, Action& selected) {
  auto a = std::make_shared<ModelArgs>();
  CLI::App* cmd = app.add_subcommand("model", "Show an axis model (poles, zeros, bandwidth) and write its frequency responses");
  cmd->add_option("model", a->model, "Model file (servotwin.axis-model/1)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--frf", a->frf,
                  "Write tracking and disturbance frequency responses (freq_hz, re, im, mag_db, phase_deg per function)");
  cmd->add_option("--fmin-hz", a->fmin_hz, "Lowest frequency of --frf [Hz]")->capture_default_str();
  cmd->add_option("--fmax-hz", a->fmax_hz, "Highest frequency of --frf [Hz] (default: Nyquist)");
  cmd->add_option("--points", a->points, "Log-spaced points of --frf")->check(CLI::Range(2, 1000000))->capture_default_str();
  set_examples(*cmd, "  servotwin model model.json\n  servotwin model model.json --frf frf.csv --fmax-hz 200\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
