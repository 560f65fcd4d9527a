#include "servotwin/motion/program.hpp"

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
