#include "servotwin/motion/program.hpp"

#include <charconv>

namespace servotwin::motion {

char axis_letter(Axis a) noexcept {
  switch (a) {
    case Axis::X: return 'X';
    case Axis::Y: return 'Y';
    case Axis::Z: return 'Z';
  }
  return '?';
}

const char* axis_name(Axis a) noexcept {
  switch (a) {
    case Axis::X: return "x";
    case Axis::Y: return "y";
    case Axis::Z: return "z";
  }
  return "?";
}

namespace {
// Both in-plane axes move on an arc, even a full circle whose end equals its start.
std::uint8_t plane_axes(Plane plane) noexcept {
  switch (plane) {
    case Plane::XY: return static_cast<std::uint8_t>(axis_bit(Axis::X) | axis_bit(Axis::Y));
    case Plane::ZX: return static_cast<std::uint8_t>(axis_bit(Axis::Z) | axis_bit(Axis::X));
    case Plane::YZ: return static_cast<std::uint8_t>(axis_bit(Axis::Y) | axis_bit(Axis::Z));
  }
  return 0;
}
}  // namespace

std::string describe_path_control(PathControl mode, double blend_tolerance_mm) {
  switch (mode) {
    case PathControl::Unstated: return "path control not stated";
    case PathControl::ExactStop: return "exact stop at every block end";
    case PathControl::ExactPath: return "exact path (stops at corners, tangent moves run on)";
    case PathControl::Blend: break;
  }
  if (!(blend_tolerance_mm > 0.0)) return "corners blended, no tolerance stated";
  char text[32];
  const auto r = std::to_chars(text, text + sizeof text, blend_tolerance_mm);
  return "corners blended within " + std::string(text, r.ptr) + " mm";
}

namespace {
bool moves(const Block& b) noexcept { return b.type != BlockType::None && b.type != BlockType::Dwell; }
}  // namespace

bool Program::states_path_control() const noexcept {
  for (const Block& b : blocks)
    if (moves(b) && b.path_control != PathControl::Unstated) return true;
  return false;
}

bool Program::blends() const noexcept {
  for (const Block& b : blocks)
    if (moves(b) && b.path_control == PathControl::Blend) return true;
  return false;
}

std::uint8_t Program::used_axes() const noexcept {
  std::uint8_t mask = 0;
  for (const Block& b : blocks) {
    mask = static_cast<std::uint8_t>(mask | b.axes);
    if (b.type == BlockType::ArcCw || b.type == BlockType::ArcCcw) mask = static_cast<std::uint8_t>(mask | plane_axes(b.plane));
    for (std::size_t i = 0; i < kAxisCount; ++i)
      if (b.type != BlockType::None && b.type != BlockType::Dwell && b.end[i] != b.start[i])
        mask = static_cast<std::uint8_t>(mask | axis_bit(static_cast<Axis>(i)));
  }
  return mask;
}

}  // namespace servotwin::motion
