#include "servotwin/machine/flexible_presets.hpp"

#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/machine/flexible_frame.hpp"

namespace servotwin::machine {

namespace {

using core::Polynomial;

// s^2 + 2 zeta omega s + omega^2.
Polynomial quadratic(double omega, double zeta) { return Polynomial{1.0, 2.0 * zeta * omega, omega * omega}; }

PlantConfig tf_plant(std::string name, std::string description, Polynomial num, Polynomial den, double ts,
                     PlantOutput output) {
  PlantConfig c;
  c.name = std::move(name);
  c.description = std::move(description);
  c.model = TransferFunctionModel{core::TransferFunction(std::move(num), std::move(den))};
  c.settings.ts = ts;
  c.settings.output = output;
  return c;
}

PlantConfig testbed_1() {
  const double k = 544.6, tau1 = 0.16, tau2 = 0.0038;
  const Polynomial num = k * (quadratic(35.3, 0.19) * quadratic(114.6, 0.11));
  const Polynomial den = Polynomial{1.0, tau1} * quadratic(70.8, 0.02) * quadratic(260.1, 0.005) * Polynomial{tau2, 1.0};
  return tf_plant("testbed-1",
                  "Dynamic test bed, configuration 1 (dissertation sec. 8.6, eq. 8.13; catalog E37): motor torque to "
                  "motor velocity, two resonances 70.8 and 260.1 rad/s, lag 1/(0.0038 s + 1); EtherCAT 2 kHz",
                  num, den, 0.0005, PlantOutput::MotorVelocity);
}

PlantConfig testbed_2() {
  const double k = 454.5, tau1 = 0.15, tau2 = 0.0022;
  const Polynomial num = k * quadratic(49.9, 0.24);
  const Polynomial den = Polynomial{1.0, tau1} * quadratic(254.0, 0.02) * Polynomial{tau2, 1.0};
  return tf_plant("testbed-2",
                  "Dynamic test bed, configuration 2 (dissertation sec. 8.6, eq. 8.14; catalog E37): motor torque to "
                  "motor velocity, resonance 254 rad/s, r = 5.09, lag 1/(0.0022 s + 1); EtherCAT 2 kHz",
                  num, den, 0.0005, PlantOutput::MotorVelocity);
}

PlantConfig gantry_crane() {
  constexpr double g = 9.80665;
  const double wn = 4.22, zeta = 0.0079;
  const double rope = g / (wn * wn);
  return tf_plant("gantry-crane",
                  "Gantry crane laboratory model (dissertation sec. 8.1; catalog A1/E35): sway angle [rad] over cart "
                  "velocity command [m/s], -(1/l) s/(s^2 + 2 xi wn s + wn^2), wn = 4.22 rad/s, xi = 0.0079, "
                  "l = g/wn^2; ts 10 ms chosen",
                  Polynomial{-1.0 / rope, 0.0}, quadratic(wn, zeta), 0.01, PlantOutput::LoadPosition);
}

PlantConfig rfid_demo() {
  const Polynomial num = Polynomial{1.0, 0.06339, 0.06057} * Polynomial{1.0, 0.1129, 2.064};
  const Polynomial den =
      Polynomial{1.0, 0.04544} * Polynomial{1.0, 0.04541, 0.9985} * Polynomial{1.0, 0.9854, 9.12};
  return tf_plant("rfid-demo",
                  "5th-order demo plant of the RFID block (dissertation sec. 5.7, eq. 5.114; catalog E14): modes "
                  "0.9992 rad/s (0.0227) and 3.0199 rad/s (0.1631); ts = 0.1 s",
                  num, den, 0.1, PlantOutput::MotorVelocity);
}

PlantConfig table_5_1() {
  PlantConfig c;
  c.name = "table-5.1";
  c.description =
      "Two-mass plant of Table 5.1 (catalog E10/E10b), (0.5 s^2 + 0.06 s + 0.5)/(s^3 + 1.1 s^2 + 9.18 s + 1.8), "
      "realised as Im = 2, Il = k = 16.126, b = 0.1476, bm = 1.8124, bl = 1.7876, with E12's Karnopp load "
      "friction TS = 3, TC = 0.5, dv = 0.02; ts 10 ms chosen";
  // The unique non-negative solution of the C3.12 coefficient equations for this TF (header).
  const double il = 16.12615039151721;
  MassChain chain = two_mass(2.0, il, il, 0.1475690234910330, 1.812430976508967, 1.787569023491033);
  chain.friction = {KarnoppFriction{}, KarnoppFriction{0.5, 3.0, 0.02}};
  c.model = chain;
  c.settings.ts = 0.01;
  c.settings.output = PlantOutput::MotorVelocity;
  return c;
}

PlantConfig motor_bench() {
  PlantConfig c;
  c.name = "motor-bench";
  c.description =
      "Two-mass servo bench: antiresonance 53 Hz, resonance 76 Hz, total inertia 0.0099 kg m^2, Karnopp "
      "friction on motor and load, current loop 0.2 ms, 8 kHz sampling, 20-bit encoder velocity with noise";
  constexpr double two_pi = 2.0 * std::numbers::pi;
  const double total = 0.0099;
  const double wz = two_pi * 53.0, wn = two_pi * 76.0;
  const double im = total / ((wn / wz) * (wn / wz));
  const double il = total - im;
  const double k = wz * wz * il;
  const double b = 2.0 * 0.02 * std::sqrt(k * il);
  MassChain chain = two_mass(im, il, k, b, 2e-4, 1e-4);
  chain.friction = {KarnoppFriction{0.02, 0.03, 0.005}, KarnoppFriction{0.01, 0.015, 0.005}};
  c.model = chain;
  c.settings.ts = 1.0 / 8000.0;
  c.settings.current_lag = 2e-4;
  c.settings.output = PlantOutput::MotorVelocity;
  c.settings.noise_std = 0.01;
  c.settings.quantization = two_pi / 1048576.0 * 8000.0;
  return c;
}

PlantConfig c7_19_frame() {
  const core::TransferFunction p = flexible_frame_transfer_function(c7_19_flexible_frame());
  PlantConfig c = tf_plant("c7.19-frame",
                  "Flexible-frame four-mass example (dissertation sec. 7.6, eq. 7.175; catalog C7.19/E34): rotor "
                  "velocity in stator coordinates per motor force, eq. 7.172, m1 = 70, k1 = 4500, b1 = 0.01, m2 = 0.2, "
                  "k2 = 5, b2 = 0.02, m3 = 0.1, k3 = 0.1, b3 = 0.01, m4 = 0.2 (inferred); modes 1.22, 5.0, 8.03 rad/s; "
                  "ts 10 ms chosen",
                  p.num(), p.den(), 0.01, PlantOutput::MotorVelocity);
  c.frame = c7_19_flexible_frame();
  return c;
}

}  // namespace

std::vector<std::string> flexible_preset_names() {
  return {"testbed-1", "testbed-2", "gantry-crane", "rfid-demo", "table-5.1", "motor-bench", "c7.19-frame"};
}

PlantConfig flexible_preset(std::string_view name) {
  if (name == "testbed-1") return testbed_1();
  if (name == "testbed-2") return testbed_2();
  if (name == "gantry-crane") return gantry_crane();
  if (name == "rfid-demo") return rfid_demo();
  if (name == "table-5.1") return table_5_1();
  if (name == "motor-bench") return motor_bench();
  if (name == "c7.19-frame") return c7_19_frame();
  std::string names;
  for (const auto& n : flexible_preset_names()) names += (names.empty() ? "" : ", ") + n;
  throw core::InputError(core::at_field("plant"), "unknown plant preset '" + std::string(name) + "' (known: " + names + ")");
}

}  // namespace servotwin::machine
