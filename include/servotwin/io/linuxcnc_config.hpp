#pragma once
/// \file
/// What a LinuxCNC configuration says about a halsampler trace: the HAL file names the signal on
/// each `sampler.N.pin.M` (its `net` lines) and the thread the sampler runs in (`addf`), the INI
/// file the threads' periods (`[EMCMOT]SERVO_PERIOD`, `BASE_PERIOD`, in ns) and which axis each
/// joint drives (`[TRAJ]COORDINATES`, or `coordinates=` of `[KINS]KINEMATICS` for trivkins).
///
/// Columns are named by servotwin's convention where the HAL file makes the meaning plain: a pin
/// on the net of `joint.J.motor-pos-cmd` (or `joint.J.pos-cmd`, 2.7's `axis.J.*`) is `<a>_cmd`,
/// on the net of `joint.J.motor-pos-fb` (`pos-fb`) `<a>_act`, on the net of the `output` of a
/// `pid.P` whose `command` is on joint J's command net `<a>_u`, with `<a>` the joint's axis letter
/// (lower case). Any other pin keeps its signal's name (or `sampler.N.pin.M` when unconnected),
/// which `--map` can still assign.
///
/// Read in the subset of halcmd the configurations use: `#` comments, `loadrt sampler ... cfg=`,
/// `addf`, `net <signal> <pin> [=> <= <=>] <pin>...`, `linkps`/`linksp`, line continuations with `\`.
/// Substitutions `[SECTION]KEY` are resolved from the INI file when one is given.

#include <optional>
#include <string>
#include <vector>

namespace servotwin::io {

/// A LinuxCNC INI file, the parts a trace needs.
struct LinuxCncIni {
  std::string path;
  std::optional<double> servo_period_s;  ///< [EMCMOT]SERVO_PERIOD
  std::optional<double> base_period_s;   ///< [EMCMOT]BASE_PERIOD
  /// Axis letter of each joint, upper case ("XYZ" when the file says nothing: trivkins' default).
  std::string joint_axes = "XYZ";
  /// Value of `[section]key`, if present (first occurrence, as LinuxCNC's inifile reads it).
  [[nodiscard]] std::optional<std::string> value(const std::string& section, const std::string& key) const;
  std::vector<std::pair<std::string, std::string>> entries;  ///< "[SECTION]KEY" -> value, in file order
};

/// Reads an INI file. core::InputError naming the file and line for a malformed period or an
/// unreadable file.
LinuxCncIni read_linuxcnc_ini(const std::string& path);

/// servotwin's name for a LinuxCNC pin that carries a joint's position: `joint.J.motor-pos-cmd` or
/// `joint.J.pos-cmd` (2.7: `axis.J.*`) -> "<a>_cmd", `motor-pos-fb` / `pos-fb` -> "<a>_act", with
/// <a> the lower-case letter of joint J in `joint_axes` ("XYZ": joint 1 is y); empty otherwise.
std::optional<std::string> joint_pin_column(const std::string& pin, const std::string& joint_axes = "XYZ");

/// A sampler's columns as a HAL file defines them.
struct HalSamplerColumns {
  std::vector<std::string> columns;  ///< one per pin, named as in the file comment
  std::vector<std::string> signals;  ///< the net of each pin, "" when unconnected
  std::string thread;                ///< where `addf sampler.N` puts it ("" when not added)
  /// Period of that thread from the INI (servo-thread: SERVO_PERIOD, base-thread: BASE_PERIOD).
  std::optional<double> period_s;
};

/// Reads sampler `sampler`'s columns from a HAL file (its pin count from `cfg=`, or the highest
/// pin the nets use). core::InputError naming the file and line when the file cannot be read,
/// loads no sampler of that index, or a `cfg=` is malformed.
HalSamplerColumns read_hal_sampler_columns(const std::string& hal_path, int sampler = 0,
                                           const LinuxCncIni* ini = nullptr);

}  // namespace servotwin::io
