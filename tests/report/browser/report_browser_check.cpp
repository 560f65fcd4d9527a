// Opens HTML reports in headless Chromium and checks that they load without errors and that every
// chart has drawn: the report's glue (web/src/report.js) records script errors, console errors and
// warnings and, per chart, whether its canvas holds curve pixels, in attributes of the root
// element; Chromium's --dump-dom prints the DOM after the page has run.
//
//   report_browser_check --library DIR      write the library's test reports into DIR and check them
//   report_browser_check --check FILE...    check existing reports (e.g. from `servotwin identify --report`)
//
// Exit status: 0 all good, 1 a check failed, 2 usage, 77 Chromium is not installed (CTest's
// SKIP_RETURN_CODE). SERVOTWIN_CHROMIUM names the browser; otherwise chromium, chromium-browser,
// google-chrome are looked up on PATH.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "servotwin/machine/presets.hpp"
#include "servotwin/motion/identification_program.hpp"
#include "servotwin/report/document.hpp"
#include "servotwin/report/identification_report.hpp"
#include "servotwin/vcnc/identification.hpp"
#include "servotwin/vcnc/machine_run.hpp"

namespace fs = std::filesystem;
using namespace servotwin;

namespace {

constexpr int kSkip = 77;

std::optional<std::string> find_chromium() {
  if (const char* env = std::getenv("SERVOTWIN_CHROMIUM"); env != nullptr && *env != '\0') return std::string(env);
  const char* path = std::getenv("PATH");
  if (path == nullptr) return std::nullopt;
  std::stringstream dirs(path);
  std::vector<std::string> entries;
  for (std::string dir; std::getline(dirs, dir, ':');) entries.push_back(dir);
  for (const char* name : {"chromium", "chromium-browser", "google-chrome", "google-chrome-stable"}) {
    for (const auto& dir : entries) {
      const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
      std::error_code ec;
      if (fs::is_regular_file(candidate, ec) && access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
  }
  return std::nullopt;
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

struct BrowserRun {
  int exit_status = -1;
  std::string dom;
  std::string log;  // Chromium's stderr
};

/// Runs Chromium once on `page`, returning the DOM it dumps. A fresh profile per run, so that
/// parallel test runs never share one.
BrowserRun dump_dom(const std::string& chromium, const fs::path& page, const fs::path& work, int budget_ms) {
  static int run = 0;
  const fs::path profile = work / ("chromium-profile-" + std::to_string(++run));
  const fs::path log = work / ("chromium-" + std::to_string(run) + ".log");
  fs::remove_all(profile);
  const std::string command =
      "timeout 240 " + shell_quote(chromium) +
      " --headless=new --no-sandbox --disable-gpu --disable-dev-shm-usage --no-first-run --no-default-browser-check"
      " --disable-extensions --disable-background-networking --disable-component-update --mute-audio"
      " --hide-scrollbars --window-size=1280,1024 --virtual-time-budget=" +
      std::to_string(budget_ms) + " --user-data-dir=" + shell_quote(profile.string()) + " --dump-dom " +
      shell_quote("file://" + fs::absolute(page).string()) + " 2>" + shell_quote(log.string());
  BrowserRun result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[65536];
  for (std::size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) result.dom.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.log = read_file(log);
  fs::remove_all(profile);
  return result;
}

/// Appended to a copy of a report: once the glue has drawn and checked the charts, drives every
/// chart like a person with synthetic mouse events on uPlot's overlay: hovering must put numbers
/// into the legend, dragging across the plot must zoom in (the x range shrinks; on path charts the
/// y range too). Results go into root attributes data-hover-ok / data-zoom-ok (charts passing).
constexpr const char* kInteractionScript = R"JS(
<script>
document.addEventListener('DOMContentLoaded', function () {
  setTimeout(function () {
    var root = document.documentElement, hover = 0, zoom = 0, notes = [];
    var charts = (window.servotwinReport && window.servotwinReport.charts) || [];
    function fire(target, type, x, y) {
      // movementX/Y: uPlot ignores motionless moves during a drag (a Chrome quirk on Windows).
      target.dispatchEvent(new MouseEvent(type, { clientX: x, clientY: y, movementX: 5, movementY: 5, bubbles: true,
        cancelable: true, view: window, button: 0, buttons: type === 'mouseup' ? 0 : 1 }));
    }
    var pending = [];
    charts.forEach(function (u, i) {
      if (!u) return;
      try {
        u.root.scrollIntoView();
        var r = u.over.getBoundingClientRect();
        var cx = r.left + r.width * 0.5, cy = r.top + r.height * 0.5;
        fire(u.over, 'mouseenter', cx, cy);
        fire(u.over, 'mousemove', cx, cy);
        var values = Array.prototype.map.call(u.root.querySelectorAll('.u-legend .u-value'), function (e) { return e.textContent; });
        if (values.some(function (v) { return /[0-9]/.test(v); })) hover++;
        else notes.push('chart ' + (i + 1) + ': hover showed no values: ' + values.join(' | '));
        var before = { x: u.scales.x.max - u.scales.x.min, y: u.scales.y.max - u.scales.y.min };
        fire(u.over, 'mousedown', r.left + r.width * 0.3, r.top + r.height * 0.3);
        fire(u.over, 'mousemove', r.left + r.width * 0.6, r.top + r.height * 0.6);
        fire(document, 'mouseup', r.left + r.width * 0.6, r.top + r.height * 0.6);
        pending.push({ u: u, i: i, before: before });
      } catch (e) {
        notes.push('chart ' + (i + 1) + ': ' + e);
      }
    });
    // uPlot applies a zoom in its next commit: look once it has run.
    setTimeout(function () {
      pending.forEach(function (p) {
        var u = p.u, x1 = u.scales.x.max - u.scales.x.min, y1 = u.scales.y.max - u.scales.y.min;
        var narrowed = u.mode === 2 ? (x1 < 0.5 * p.before.x && y1 < 0.5 * p.before.y) : x1 < 0.5 * p.before.x;
        if (narrowed) zoom++;
        else notes.push('chart ' + (p.i + 1) + ': drag did not zoom: x ' + p.before.x + ' to ' + x1 + ', y ' + p.before.y + ' to ' + y1);
      });
      root.setAttribute('data-hover-ok', String(hover));
      root.setAttribute('data-zoom-ok', String(zoom));
      root.setAttribute('data-interaction-notes', notes.join('; '));
    }, 50);
  }, 50);
});
</script>
)JS";

/// Attributes of the dumped page's root element (plain parsing: std::regex trips GCC 12's
/// -Wmaybe-uninitialized under the sanitizers).
std::map<std::string, std::string> root_attributes(const std::string& dom) {
  std::map<std::string, std::string> attributes;
  const std::size_t begin = dom.find("<html");
  if (begin == std::string::npos) return attributes;
  const std::size_t end = dom.find('>', begin);
  if (end == std::string::npos) return attributes;
  const std::string tag = dom.substr(begin, end - begin);
  for (std::size_t at = tag.find("=\""); at != std::string::npos; at = tag.find("=\"", at + 2)) {
    std::size_t name_begin = at;
    while (name_begin > 0 && tag[name_begin - 1] != ' ') --name_begin;
    const std::size_t value_end = tag.find('"', at + 2);
    if (value_end == std::string::npos) break;
    attributes[tag.substr(name_begin, at - name_begin)] = tag.substr(at + 2, value_end - at - 2);
    at = value_end - 1;
  }
  return attributes;
}

std::string error_box(const std::string& dom) {
  const std::size_t begin = dom.find("<pre id=\"report-errors\"");
  if (begin == std::string::npos) return {};
  const std::size_t content = dom.find('>', begin);
  const std::size_t end = dom.find("</pre>", begin);
  if (content == std::string::npos || end == std::string::npos || end < content) return {};
  return dom.substr(content + 1, end - content - 1);
}

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++n;
  return n;
}

/// Hover and drag-zoom on every drawn chart of a copy of `page` with kInteractionScript added.
bool check_interaction(const std::string& chromium, const fs::path& page, const fs::path& work, std::size_t drawn) {
  std::string html = read_file(page);
  const std::size_t body_end = html.rfind("</body>");
  if (body_end == std::string::npos) {
    std::cout << "  no </body> in the report" << std::endl;
    return false;
  }
  html.insert(body_end, kInteractionScript);
  const fs::path copy = work / (page.stem().string() + ".interaction.html");
  {
    std::ofstream out(copy, std::ios::binary);
    out << html;
  }
  std::map<std::string, std::string> attributes;
  for (int budget_ms : {20000, 60000}) {
    attributes = root_attributes(dump_dom(chromium, copy, work, budget_ms).dom);
    if (attributes.count("data-zoom-ok")) break;
    std::cout << "  the interaction test did not finish, retrying with a larger time budget" << std::endl;
  }
  bool ok = true;
  for (const char* name : {"data-hover-ok", "data-zoom-ok"}) {
    const std::string got = attributes.count(name) ? attributes[name] : "(missing)";
    std::cout << "  " << name << " = " << got << (got == std::to_string(drawn) ? "" : "   EXPECTED " + std::to_string(drawn))
              << std::endl;
    ok = ok && got == std::to_string(drawn);
  }
  if (!attributes["data-interaction-notes"].empty()) std::cout << "  " << attributes["data-interaction-notes"] << std::endl;
  const std::string errors = attributes.count("data-errors") ? attributes["data-errors"] : "(missing)";
  if (errors != "0") {
    std::cout << "  errors while interacting: " << errors << std::endl;
    ok = false;
  }
  return ok;
}

/// Checks one report: no errors, every chart either drawn or (only `expected_empty` of them)
/// empty for lack of finite data. Prints what it found.
bool check_report(const std::string& chromium, const fs::path& page, const fs::path& work, std::size_t expected_charts,
                  std::size_t expected_empty) {
  std::cout << page.filename().string() << ": " << expected_charts << " charts expected";
  if (expected_empty > 0) std::cout << " (" << expected_empty << " without finite data)";
  std::cout << std::endl;
  BrowserRun run;
  std::map<std::string, std::string> attributes;
  // Chromium on a loaded 2-core machine can be slow to start: a run that ends before the page has
  // settled (no final status) is repeated with more time; a page that settled is judged at once.
  for (int budget_ms : {20000, 60000}) {
    run = dump_dom(chromium, page, work, budget_ms);
    attributes = root_attributes(run.dom);
    const std::string status = attributes.count("data-report-status") ? attributes["data-report-status"] : "";
    if (status == "ok" || status == "failed") break;
    std::cout << "  Chromium exited with " << run.exit_status << " before the page settled (status '" << status
              << "'), retrying with a larger time budget" << std::endl;
  }
  bool ok = true;
  const auto expect = [&](const std::string& name, const std::string& wanted) {
    const std::string got = attributes.count(name) ? attributes[name] : "(missing)";
    std::cout << "  " << name << " = " << got << (got == wanted ? "" : "   EXPECTED " + wanted) << std::endl;
    ok = ok && got == wanted;
  };
  expect("data-report-status", "ok");
  expect("data-errors", "0");
  expect("data-charts", std::to_string(expected_charts));
  expect("data-charts-drawn", std::to_string(expected_charts - expected_empty));
  expect("data-charts-empty", std::to_string(expected_empty));
  const std::size_t marked = count(run.dom, "data-drawn=\"true\"");
  std::cout << "  figures marked drawn: " << marked << std::endl;
  ok = ok && marked == expected_charts - expected_empty;
  if (!ok) {
    std::cout << "  errors recorded by the page:\n" << error_box(run.dom) << "\n  Chromium exit status "
              << run.exit_status << ", log:\n" << run.log << std::endl;
    return false;
  }
  return check_interaction(chromium, page, work, expected_charts - expected_empty);
}

// ---- the library's test reports --------------------------------------------------------------

report::Document identification_document() {
  const machine::MachineConfig machine = machine::preset("fadal-pid");
  const auto capture = [&](std::uint64_t seed, std::size_t moves) {
    motion::IdentificationOptions o = motion::identification_defaults(motion::IdentificationSet::Standard);
    o.axes = {motion::Axis::X};
    o.seed = seed;
    o.moves = moves;
    return vcnc::NamedCapture{"fadal-pid seed " + std::to_string(seed),
                              vcnc::run_program(machine, motion::make_identification_program(o))};
  };
  const std::vector<vcnc::NamedCapture> captures = {capture(7, 200)};
  const std::vector<vcnc::NamedCapture> validation = {capture(11, 80)};
  vcnc::IdentificationSettings settings;
  settings.shift_search = vcnc::ShiftSearch{};
  const vcnc::AxisIdentification id = vcnc::identify_axis(captures, validation, "x", settings);
  return report::identification_report(id, captures, validation);
}

/// Every kind of chart the writer makes: long decimated time series with gaps, log axes, a long
/// XY path (simplified) with a gap, hostile labels, and one chart without finite data.
report::Document feature_document() {
  constexpr std::size_t n = 600000;  // 10 minutes at 1 kHz
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  report::Document doc;
  doc.title = "Feature test </script><script>alert(1)</script> \xC2\xB5m \"quoted\"";
  doc.subtitle = "every chart kind of the report writer";
  report::Section time;
  time.title = "Long time series";
  time.text = "Three axes, 600 000 samples each, with a gap.";
  report::Chart errors;
  errors.title = "Tracking errors </script>";
  errors.x_label = "time [s]";
  errors.y_label = "error [\xC2\xB5m]";
  for (int axis = 0; axis < 3; ++axis) {
    report::Series s{std::string("axis ") + "xyz"[axis], std::vector<double>(n), std::vector<double>(n)};
    for (std::size_t k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) * 1e-3;
      s.x[k] = t;
      s.y[k] = 3.0 * std::sin(2.0 * std::numbers::pi * 0.05 * (axis + 1) * t) + 0.3 * std::sin(377.0 * t + axis);
    }
    for (std::size_t k = 200000; k < 201000; ++k) s.y[k] = nan;
    errors.series.push_back(std::move(s));
  }
  time.charts.push_back(std::move(errors));
  report::Chart offset;  // series with different x grids on one chart
  offset.title = "Series on different grids";
  offset.x_label = "time [s]";
  offset.y_label = "value";
  offset.series.push_back({"coarse", {0.0, 1.0, 2.0, 3.0, 4.0}, {0.0, 1.0, 0.0, 1.0, 0.0}});
  offset.series.push_back({"fine", {0.5, 1.5, 2.5, 3.5}, {0.5, 0.25, 0.75, 0.5}});
  time.charts.push_back(std::move(offset));
  doc.sections.push_back(std::move(time));

  report::Section frequency;
  frequency.title = "Logarithmic axes";
  report::Chart bode;
  bode.title = "First-order low pass, 10 Hz";
  bode.x_label = "frequency [Hz]";
  bode.y_label = "|G|";
  bode.x_scale = report::Scale::Log;
  bode.y_scale = report::Scale::Log;
  report::Series g{"|G|", {}, {}};
  for (int i = 0; i <= 400; ++i) {
    const double f = std::pow(10.0, -1.0 + 4.0 * i / 400.0);
    g.x.push_back(f);
    g.y.push_back(1.0 / std::hypot(1.0, f / 10.0));
  }
  bode.series.push_back(std::move(g));
  frequency.charts.push_back(std::move(bode));
  doc.sections.push_back(std::move(frequency));

  report::Section path;
  path.title = "XY path";
  report::Chart xy;
  xy.title = "Contour with the error magnified 500x";
  xy.x_label = "x [mm]";
  xy.y_label = "y [mm]";
  xy.equal_axes = true;
  report::Series commanded{"commanded", std::vector<double>(n), std::vector<double>(n)};
  report::Series actual{"actual (error x500)", std::vector<double>(n), std::vector<double>(n)};
  for (std::size_t k = 0; k < n; ++k) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    commanded.x[k] = 40.0 * std::cos(a);
    commanded.y[k] = 25.0 * std::sin(2.0 * a);
    const double e = 500.0 * 0.004 * std::sin(7.0 * a);
    actual.x[k] = commanded.x[k] + e * std::cos(a);
    actual.y[k] = commanded.y[k] + e * std::sin(a);
  }
  for (std::size_t k = 300000; k < 300500; ++k) actual.x[k] = nan;
  xy.series.push_back(std::move(commanded));
  xy.series.push_back(std::move(actual));
  path.charts.push_back(std::move(xy));
  report::Chart empty;
  empty.title = "Nothing finite to draw";
  empty.series.push_back({"nan", {0.0, 1.0, 2.0}, {nan, nan, nan}});
  path.charts.push_back(std::move(empty));
  doc.sections.push_back(std::move(path));
  return doc;
}

int library_reports(const std::string& chromium, const fs::path& dir) {
  fs::create_directories(dir);
  struct Case {
    const char* file;
    report::Document doc;
    std::size_t empty;
  };
  std::vector<Case> cases;
  cases.push_back({"identification.html", identification_document(), 0});
  cases.push_back({"features.html", feature_document(), 1});
  bool ok = true;
  for (const Case& c : cases) {
    const fs::path page = dir / c.file;
    {
      std::ofstream out(page, std::ios::binary);
      report::write_html(out, c.doc);
    }
    std::cout << "wrote " << page.string() << " (" << fs::file_size(page) << " bytes)" << std::endl;
    ok = check_report(chromium, page, dir, report::chart_count(c.doc), c.empty) && ok;
  }
  return ok ? 0 : 1;
}

int existing_reports(const std::string& chromium, const std::vector<std::string>& files) {
  bool ok = true;
  for (const auto& file : files) {
    const fs::path page = fs::absolute(file);
    const std::string html = read_file(page);
    if (html.empty()) {
      std::cout << file << ": missing or empty" << std::endl;
      ok = false;
      continue;
    }
    // The charts the page should draw: its chart figures, counted in the source.
    const std::size_t expected = count(html, "<figure class=\"chart");
    if (expected == 0) {
      std::cout << file << ": no charts in the report" << std::endl;
      ok = false;
      continue;
    }
    ok = check_report(chromium, page, page.parent_path(), expected, 0) && ok;
  }
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() < 2 || (args[0] != "--library" && args[0] != "--check")) {
    std::cerr << "usage: report_browser_check --library DIR | --check FILE.html...\n";
    return 2;
  }
  const std::optional<std::string> chromium = find_chromium();
  if (!chromium) {
    std::cout << "SKIPPED: Chromium is not installed (scripts/install-deps.sh --test installs Debian's chromium), "
                 "so the reports cannot be opened in a browser"
              << std::endl;
    return kSkip;
  }
  try {
    if (args[0] == "--library") return library_reports(*chromium, args[1]);
    return existing_reports(*chromium, std::vector<std::string>(args.begin() + 1, args.end()));
  } catch (const std::exception& e) {
    std::cout << "error: " << e.what() << std::endl;
    return 1;
  }
}
