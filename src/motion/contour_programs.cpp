#include "servotwin/motion/contour_programs.hpp"

#include <cmath>
#include <string>

#include "gcode_common.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::motion {

namespace {

void validate(const ContourProgramOptions& o) {
  const auto fail = [](const char* field, const std::string& message) {
    throw core::InputError(core::at_field(field), message);
  };
  if (!std::isfinite(o.size_mm) || o.size_mm <= 0.0) fail("size_mm", "must be a finite length > 0 mm");
  if (!std::isfinite(o.feed_mm_min) || o.feed_mm_min <= 0.0 || o.feed_mm_min > 1e9)
    fail("feed_mm_min", "must lie in (0, 1e9] mm/min");
  for (double c : o.center)
    if (!std::isfinite(c)) fail("center", "must be finite");
}

/// Appends blocks, each starting where the previous one ended, numbered N0, N10, ...
class ProgramBuilder {
 public:
  ProgramBuilder(const ContourProgramOptions& o, const char* name) {
    program_.name = name;
    program_.dialect = o.dialect;
    program_.start = o.center;
    at_ = o.center;
  }
  void move(BlockType type, const Point& end, double feed, const Point& center = {}) {
    Block b;
    b.type = type;
    b.start = at_;
    b.end = end;
    b.center = type == BlockType::ArcCcw || type == BlockType::ArcCw ? center : at_;
    b.plane = Plane::XY;
    b.feed_mm_min = feed;
    b.axes = axis_bit(Axis::X) | axis_bit(Axis::Y);
    add(std::move(b));
  }
  Program finish() {
    Block end;
    end.start = end.end = end.center = at_;
    end.m_codes.push_back(30);
    add(std::move(end));
    return std::move(program_);
  }

 private:
  void add(Block b) {
    b.number = number_;
    number_ += 10;
    at_ = b.end;
    program_.blocks.push_back(std::move(b));
  }
  Program program_;
  Point at_{};
  long number_ = 0;
};

Point offset(const Point& c, double dx, double dy) { return {c[0] + dx, c[1] + dy, c[2]}; }

}  // namespace

namespace {

/// Positions the tool at the rightmost point of the toolpath, runs `body` from there, returns to
/// the centre and ends the program.
template <typename Body>
Program closed_toolpath(const ContourProgramOptions& o, const char* name, Body body) {
  validate(o);
  const double r = 0.5 * o.size_mm;
  ProgramBuilder p(o, name);
  const Point first = offset(o.center, r, 0.0);
  p.move(BlockType::Rapid, first, o.feed_mm_min);
  body(p, r, first);
  p.move(BlockType::Rapid, o.center, o.feed_mm_min);
  Program program = p.finish();
  detail::state_path_control(program, o.path_control, o.blend_tolerance_mm);
  return program;
}

}  // namespace

Program make_circle_program(const ContourProgramOptions& o) {
  return closed_toolpath(o, "circle", [&](ProgramBuilder& p, double, const Point& first) {
    p.move(BlockType::ArcCcw, first, o.feed_mm_min, o.center);
  });
}

Program make_diamond_program(const ContourProgramOptions& o) {
  return closed_toolpath(o, "diamond", [&](ProgramBuilder& p, double r, const Point& first) {
    p.move(BlockType::Linear, offset(o.center, 0.0, r), o.feed_mm_min);
    p.move(BlockType::Linear, offset(o.center, -r, 0.0), o.feed_mm_min);
    p.move(BlockType::Linear, offset(o.center, 0.0, -r), o.feed_mm_min);
    p.move(BlockType::Linear, first, o.feed_mm_min);
  });
}

}  // namespace servotwin::motion
