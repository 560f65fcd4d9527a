#include "servotwin/io/linuxcnc_config.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <sstream>

#include "servotwin/core/error.hpp"
#include "servotwin/io/program_file.hpp"

namespace servotwin::io {

namespace {

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string> tokens_of(std::string_view line) {
  std::vector<std::string> out;
  std::istringstream in{std::string(line)};
  std::string t;
  while (in >> t) out.push_back(t);
  return out;
}

/// Axis letters of the joints from COORDINATES-style text ("X Y Z", "XYZ", "XYYZ").
std::string axis_letters(std::string_view text) {
  std::string out;
  for (const char c : text)
    if (std::string_view("XYZABCUVWxyzabcuvw").find(c) != std::string_view::npos)
      out += static_cast<char>(c >= 'a' ? c - 'a' + 'A' : c);
  return out;
}

double period_of(const std::string& path, std::size_t line, const std::string& key, const std::string& text) {
  double ns = 0.0;
  const std::string_view t = trim(text);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), ns);
  if (r.ec != std::errc{} || r.ptr != t.data() + t.size() || !(ns > 0.0) || !std::isfinite(ns))
    throw core::InputError({path, line, 0, "[EMCMOT]" + key}, "expected a period in ns > 0, found '" + std::string(t) + "'");
  return ns * 1e-9;
}

}  // namespace

std::optional<std::string> LinuxCncIni::value(const std::string& section, const std::string& key) const {
  const std::string wanted = "[" + section + "]" + key;
  for (const auto& [k, v] : entries)
    if (k == wanted) return v;
  return std::nullopt;
}

LinuxCncIni read_linuxcnc_ini(const std::string& path) {
  LinuxCncIni ini;
  ini.path = path;
  std::istringstream in(read_text_file(path, std::size_t{16} << 20));
  std::string line, section;
  std::size_t number = 0;
  std::map<std::string, std::size_t> lines;
  while (std::getline(in, line)) {
    ++number;
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#' || t.front() == ';') continue;
    if (t.front() == '[') {
      const std::size_t close = t.find(']');
      if (close == std::string_view::npos)
        throw core::InputError({path, number, 1, ""}, "section name without ']': '" + std::string(t.substr(0, 40)) + "'");
      section = std::string(t.substr(1, close - 1));
      continue;
    }
    const std::size_t eq = t.find('=');
    if (eq == std::string_view::npos) continue;  // LinuxCNC ignores such lines too
    const std::string key(trim(t.substr(0, eq)));
    const std::string full = "[" + section + "]" + key;
    if (lines.count(full) != 0) continue;  // the first occurrence counts
    lines[full] = number;
    ini.entries.emplace_back(full, std::string(trim(t.substr(eq + 1))));
  }
  if (const auto v = ini.value("EMCMOT", "SERVO_PERIOD")) ini.servo_period_s = period_of(path, lines["[EMCMOT]SERVO_PERIOD"], "SERVO_PERIOD", *v);
  if (const auto v = ini.value("EMCMOT", "BASE_PERIOD")) ini.base_period_s = period_of(path, lines["[EMCMOT]BASE_PERIOD"], "BASE_PERIOD", *v);
  if (const auto v = ini.value("TRAJ", "COORDINATES")) ini.joint_axes = axis_letters(*v);
  if (const auto v = ini.value("KINS", "KINEMATICS")) {
    const std::size_t c = v->find("coordinates=");
    if (c != std::string::npos) ini.joint_axes = axis_letters(tokens_of(v->substr(c + 12)).front());
  }
  if (ini.joint_axes.empty()) ini.joint_axes = "XYZ";
  return ini;
}

namespace {

/// halcmd lines with comments removed and `\` continuations joined, with their first line numbers.
std::vector<std::pair<std::size_t, std::string>> hal_lines(const std::string& text) {
  std::vector<std::pair<std::size_t, std::string>> out;
  std::istringstream in(text);
  std::string line, pending;
  std::size_t number = 0, first = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::string_view t = trim(line);
    const bool continued = !t.empty() && t.back() == '\\';
    if (continued) t.remove_suffix(1);
    if (pending.empty()) first = number;
    pending += std::string(t) + " ";
    if (continued) continue;
    if (!trim(pending).empty()) out.emplace_back(first, pending);
    pending.clear();
  }
  if (!trim(pending).empty()) out.emplace_back(first, pending);
  return out;
}

/// `[SECTION]KEY` resolved from the INI (as halcmd -i does), else kept.
std::string substituted(const std::string& token, const LinuxCncIni* ini) {
  if (ini == nullptr || token.size() < 4 || token.front() != '[') return token;
  const std::size_t close = token.find(']');
  if (close == std::string::npos) return token;
  const auto v = ini->value(token.substr(1, close - 1), token.substr(close + 1));
  return v ? *v : token;
}

bool is_arrow(const std::string& t) { return t == "=>" || t == "<=" || t == "<=>"; }

/// "joint.2.motor-pos-cmd" -> {2, "motor-pos-cmd"} (also "axis.N.*" of LinuxCNC 2.7).
std::optional<std::pair<std::size_t, std::string>> joint_pin(const std::string& pin) {
  for (const std::string_view prefix : {"joint.", "axis."}) {
    if (pin.rfind(prefix, 0) != 0) continue;
    const std::size_t dot = pin.find('.', prefix.size());
    if (dot == std::string::npos) return std::nullopt;
    std::size_t j = 0;
    const auto r = std::from_chars(pin.data() + prefix.size(), pin.data() + dot, j);
    if (r.ec != std::errc{} || r.ptr != pin.data() + dot) return std::nullopt;
    return std::make_pair(j, pin.substr(dot + 1));
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> joint_pin_column(const std::string& pin, const std::string& joint_axes) {
  const auto jp = joint_pin(pin);
  if (!jp || jp->first >= joint_axes.size()) return std::nullopt;
  const std::string axis(1, static_cast<char>(std::tolower(static_cast<unsigned char>(joint_axes[jp->first]))));
  if (jp->second == "motor-pos-cmd" || jp->second == "pos-cmd") return axis + "_cmd";
  if (jp->second == "motor-pos-fb" || jp->second == "pos-fb") return axis + "_act";
  return std::nullopt;
}

HalSamplerColumns read_hal_sampler_columns(const std::string& hal_path, int sampler, const LinuxCncIni* ini) {
  const std::string text = read_text_file(hal_path, std::size_t{16} << 20);
  const std::string prefix = "sampler." + std::to_string(sampler) + ".pin.";
  std::map<std::string, std::string> net_of;  // pin -> signal
  std::optional<std::size_t> pins;
  std::size_t highest = 0;
  bool loaded = false;
  HalSamplerColumns out;
  for (const auto& [number, line] : hal_lines(text)) {
    std::vector<std::string> t = tokens_of(line);
    for (auto& token : t) token = substituted(token, ini);
    if (t.empty()) continue;
    if (t[0] == "loadrt" && t.size() >= 2 && t[1] == "sampler") {
      loaded = true;
      for (std::size_t i = 2; i < t.size(); ++i) {
        if (t[i].rfind("cfg=", 0) != 0) continue;
        std::vector<std::string> cfgs;
        std::stringstream list(t[i].substr(4));
        std::string c;
        while (std::getline(list, c, ',')) cfgs.push_back(c);
        if (static_cast<std::size_t>(sampler) >= cfgs.size())
          throw core::InputError({hal_path, number, 0, "cfg"},
                                 fmt::format("loadrt sampler cfg= defines {} sampler(s), not sampler.{}", cfgs.size(), sampler));
        const std::string& cfg = cfgs[static_cast<std::size_t>(sampler)];
        for (const char ch : cfg)
          if (std::string_view("fFbBuUsSrRlLkK").find(ch) == std::string_view::npos)
            throw core::InputError({hal_path, number, 0, "cfg"}, "sampler cfg '" + cfg + "': unknown type letter '" +
                                                                    std::string(1, ch) + "' (f, b, u, s)");
        pins = cfg.size();
      }
    } else if (t[0] == "addf" && t.size() >= 3 && t[1] == "sampler." + std::to_string(sampler)) {
      out.thread = t[2];
    } else if (t[0] == "net" && t.size() >= 3) {
      for (std::size_t i = 2; i < t.size(); ++i)
        if (!is_arrow(t[i])) net_of[t[i]] = t[1];
    } else if ((t[0] == "linkps" || t[0] == "linksp") && t.size() >= 3) {
      const bool pin_first = t[0] == "linkps";
      net_of[pin_first ? t[1] : t[2]] = pin_first ? t[2] : t[1];
    }
  }
  if (!loaded) throw core::InputError({hal_path, 0, 0, "loadrt sampler"}, "the HAL file loads no sampler");
  for (const auto& [pin, signal] : net_of) {
    if (pin.rfind(prefix, 0) != 0) continue;
    std::size_t m = 0;
    const auto r = std::from_chars(pin.data() + prefix.size(), pin.data() + pin.size(), m);
    if (r.ec == std::errc{} && r.ptr == pin.data() + pin.size()) highest = std::max(highest, m + 1);
  }
  const std::size_t count = pins.value_or(highest);
  if (count == 0) throw core::InputError({hal_path, 0, 0, "sampler." + std::to_string(sampler)}, "sampler." + std::to_string(sampler) + " has no pins in the HAL file");

  // Our names for the nets of the joints' command and feedback and of the pids' outputs.
  const std::string axes = ini != nullptr ? ini->joint_axes : std::string("XYZ");
  std::map<std::string, std::string> ours;  // signal -> our name
  std::map<std::string, std::size_t> command_net_joint;
  for (const auto& [pin, signal] : net_of) {
    const auto column = joint_pin_column(pin, axes);
    if (!column) continue;
    ours.emplace(signal, *column);
    if (column->ends_with("_cmd")) command_net_joint.emplace(signal, joint_pin(pin)->first);
  }
  for (const auto& [pin, signal] : net_of) {
    if (pin.rfind("pid.", 0) != 0 || pin.size() < 11 || pin.compare(pin.size() - 7, 7, ".output") != 0) continue;
    const std::string pid = pin.substr(0, pin.size() - 7);
    const auto cmd = net_of.find(pid + ".command");
    if (cmd == net_of.end()) continue;
    const auto joint = command_net_joint.find(cmd->second);
    if (joint == command_net_joint.end()) continue;
    ours.emplace(signal, std::string(1, static_cast<char>(axes[joint->second] - 'A' + 'a')) + "_u");
  }
  std::vector<std::string> used;
  for (std::size_t m = 0; m < count; ++m) {
    const std::string pin = prefix + std::to_string(m);
    const auto net = net_of.find(pin);
    const std::string signal = net == net_of.end() ? std::string() : net->second;
    std::string name = signal.empty() ? pin : signal;
    const auto our = ours.find(signal);
    if (our != ours.end() && std::find(used.begin(), used.end(), our->second) == used.end()) name = our->second;
    used.push_back(name);
    out.columns.push_back(name);
    out.signals.push_back(signal);
  }
  if (ini != nullptr) {
    if (out.thread == "servo-thread") out.period_s = ini->servo_period_s;
    if (out.thread == "base-thread") out.period_s = ini->base_period_s;
  }
  return out;
}

}  // namespace servotwin::io
