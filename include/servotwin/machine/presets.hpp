#pragma once
/// \file
/// Named virtual machines. The Fadal VMC 2216 presets reproduce the "actual" closed-loop columns
/// of thesis Tables 3.3 (P-PI), 3.4 (PID) and 3.5 (sliding mode) exactly; `ballscrew-zpetc` is
/// the ball-screw drive of thesis section 3.4.2 (pole placement at 30 Hz / 0.7 with a Kalman
/// disturbance observer and ZPETC, ts = 1 ms).
///
/// Derivation (the thesis gives only closed-loop coefficients): every axis has J = 0.1 N s^2/mm
/// (a 100 kg table) and K = 100 N/V, so K/J = 1000; the remaining parameters are solved exactly
/// from the printed columns, so the continuous closed loops match them to the printed digits:
///  * fadal-pid (Table 3.4, no feedforward): kd = b1 J/K, kp = a2 J/K, ki = a3 J/K,
///    B/J = a1 - b1 (X 2.55, Y 2.90 1/s);
///  * fadal-ppi (Table 3.3, no feedforward): K ki/J = a2 - b2, kp = a3/(a2 - b2) (= 30.000),
///    K kv/J = b2/kp, B/J = a1 - K kv/J (X 2.549, Y 2.899);
///  * fadal-smc (Table 3.5, full feedforward, model = plant): lambda = the real root of
///    s^3 + a1 s^2 + a2 s + a3 (~200 rad/s), (B + K ks)/J = a1 - lambda, K rho/J = a3/lambda,
///    with B/J of the PID table;
///  * friction F+ = d0 J, F- = d1 J (X 441/-302, Y 409/-388 mm/s^2), stiction = Coulomb level.
/// Fadal nonlinearities: saturation +-10 V, 16-bit DAC over +-10 V, 1 um encoder, no encoder
/// noise (quantization is the measurement noise), no backlash, no computation delay.
/// ballscrew-zpetc: B/J = 1.890596 1/s puts the zero of the ZOH plant K/(s (J s + B)) at the
/// thesis's z1 = -0.99937 (ts = 1 ms); K/J = 1000 as above (chosen: 10 V give 10 m/s^2);
/// friction 1030 / -1000 mm/s^2, the level Table 4.2 identified (LM 1032.57/-996.03); encoder
/// 1.25 um (thesis), saturation and DAC as the Fadal; Kalman settings at their defaults (observer
/// poles at |z| = 0.61, 0.61, 0.37). The thesis had one drive and ran X and Y trajectories
/// separately; the preset has identical x and y axes so XY contours run in one simulation.
/// Every preset: ts = 1 ms, CNC acceleration 2000 mm/s^2, no jerk limit, rapids 12000 mm/min.

#include <string>
#include <string_view>
#include <vector>

#include "servotwin/machine/axis_config.hpp"

namespace servotwin::machine {

/// Names of all presets: fadal-ppi, fadal-pid, fadal-smc, ballscrew-zpetc.
std::vector<std::string> preset_names();
/// The preset with that name; throws core::InputError listing the known names otherwise.
MachineConfig preset(std::string_view name);

}  // namespace servotwin::machine
