#pragma once
/// \file
/// Named flexible plants: the laboratory systems of the dissertation (seed2 catalog) and a
/// realistic two-mass servo bench. Every value and its source:
///
///  * testbed-1 (E37, eq. 8.13, A6 configuration 1): transfer function from motor torque to motor
///    velocity, K/(s + tau1) (s^2 + 2 xz1 wz1 s + wz1^2)/(s^2 + 2 x1 w1 s + w1^2)
///    (s^2 + 2 xz2 wz2 s + wz2^2)/(s^2 + 2 x2 w2 s + w2^2) 1/(tau2 s + 1) with K = 544.6,
///    tau1 = 0.16 1/s (a pole location as the catalog prescribes, defect 29), tau2 = 0.0038 s,
///    xz1 = 0.19, wz1 = 35.3, x1 = 0.02, w1 = 70.8, xz2 = 0.11, wz2 = 114.6, x2 = 0.005,
///    w2 = 260.1 rad/s; ts = 0.5 ms (EtherCAT at 2 kHz, A6). tau2 is the lag's time constant
///    (printed "0.0038 s", the lag that "lumps sampling, communication and actuator lag": a pole at
///    263 rad/s), not a pole location as the printed 1/(s + tau2) would have it: a pole at 0.0038
///    rad/s makes the motor velocity integrate the torque twice over the whole band, a plant the
///    dissertation's own swept-sine identification of this bed (20 points, Fig. 8.19) could not
///    have measured (our experiment on that reading left its range within 5 s), and a lag of
///    2-4 ms is what a 2 kHz EtherCAT loop with its drives adds.
///  * testbed-2 (E37, eq. 8.14, configuration 2): K = 454.5, tau1 = 0.15 1/s, tau2 = 0.0022 s,
///    xz1 = 0.24, wz1 = 49.9, x1 = 0.02, w1 = 254 rad/s; ts = 0.5 ms.
///  * gantry-crane (A1, E35): sway angle over cart velocity, K s/(s^2 + 2 xi wn s + wn^2) with
///    wn = 4.22 rad/s, xi = 0.0079, K = -1/l, l = g/wn^2 (g = 9.80665 m/s^2, l = 0.5507 m). The
///    input is the cart velocity command (a velocity-controlled cart), the output the sway angle
///    [rad] (labelled load_position). ts = 10 ms (chosen; not printed).
///  * rfid-demo (E14, eq. 5.114): F(s) = (s^2 + 0.06339 s + 0.06057)(s^2 + 0.1129 s + 2.064) /
///    ((s + 0.04544)(s^2 + 0.04541 s + 0.9985)(s^2 + 0.9854 s + 9.12)), ts = 0.1 s (E14).
///  * table-5.1 (E10/E10b, E12): the two-mass plant of Table 5.1, (0.5/(s + 0.2))
///    (s^2 + 0.12 s + 1)/(s^2 + 0.9 s + 9) = (0.5 s^2 + 0.06 s + 0.5)/(s^3 + 1.1 s^2 + 9.18 s + 1.8),
///    realised physically (C3.12 with friction: matching a3..a0 and the numerator gives
///    Im = 2, Il = k = 16.12615039151721, b = 0.1475690234910330, bm = 1.812430976508967,
///    bl = 1.787569023491033, the unique realization with all parameters >= 0), so that E12's
///    Karnopp load friction TS = 3, TC = 0.5, dv = 0.02 can act on the load. ts = 10 ms (chosen;
///    E12 does not print it).
///  * motor-bench: a physical two-mass servo bench like the FdiTools motor example (values from the
///    task brief, not from FdiTools sources): antiresonance 53 Hz, resonance 76 Hz, rigid inertia
///    Im + Il = 0.0099 kg m^2, so r^2 = (76/53)^2, Im = J/r^2 = 4.8146e-3, Il = J - Im =
///    5.0854e-3 kg m^2, k = (2 pi 53)^2 Il = 563.95 N m/rad; shaft damping for xz = 0.02
///    (b = 2 xz sqrt(k Il) = 0.06774 N m s/rad); viscous 2e-4 / 1e-4 N m s/rad; Karnopp friction
///    motor TC = 0.02, TS = 0.03 N m, load TC = 0.01, TS = 0.015 N m, dv = 0.005 rad/s; current
///    loop 0.2 ms (C3.2: rise time hundreds of us); ts = 125 us (8 kHz); output motor velocity
///    with noise std 0.01 rad/s and the velocity step of a 20-bit encoder differenced at 8 kHz,
///    2 pi / 2^20 * 8000 = 0.04794 rad/s.
///  * c7.19-frame (C7.19, eq. 7.175, E34): the flexible-frame four-mass example as its rotor
///    velocity per motor force (flexible_frame.hpp, eq. 7.172), with the inferred m4 = 0.2;
///    ts = 10 ms (chosen; not printed).

#include <string>
#include <string_view>
#include <vector>

#include "servotwin/machine/flexible_plant.hpp"

namespace servotwin::machine {

/// Names of all flexible presets: testbed-1, testbed-2, gantry-crane, rfid-demo, table-5.1,
/// motor-bench.
std::vector<std::string> flexible_preset_names();

/// The preset with that name (its description says where the numbers come from); throws
/// core::InputError listing the known names otherwise.
PlantConfig flexible_preset(std::string_view name);

}  // namespace servotwin::machine
