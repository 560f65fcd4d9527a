// The HTML writer: structure, escaping, non-finite values, axis rules, size, input errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "report_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/report/document.hpp"

namespace servotwin::report {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace html_test {

using testing::chart_data;
using testing::count;
using testing::data_text;
using testing::render;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Series ramp(const std::string& label, std::size_t n, double slope = 1.0) {
  Series s{label, {}, {}};
  for (std::size_t k = 0; k < n; ++k) {
    s.x.push_back(static_cast<double>(k) * 0.001);
    s.y.push_back(slope * static_cast<double>(k));
  }
  return s;
}

Document small_document() {
  Document doc;
  doc.title = "A report";
  doc.subtitle = "from test data";
  Section a;
  a.title = "First";
  a.text = "One paragraph.\n\nAnother one,\nwith a line break.";
  a.tables.push_back({"numbers", {"name", "value"}, {{"one", "1"}, {"two", "2"}}});
  Chart line;
  line.title = "Line chart";
  line.x_label = "time [s]";
  line.y_label = "position [mm]";
  line.series = {ramp("a", 100), ramp("b", 50, 2.0)};
  a.charts.push_back(line);
  Section b;
  b.title = "Second";
  Chart path;
  path.title = "Path";
  path.equal_axes = true;
  path.series.push_back({"circle", {1.0, 0.0, -1.0, 0.0, 1.0}, {0.0, 1.0, 0.0, -1.0, 0.0}});
  b.charts.push_back(path);
  Chart bode;
  bode.title = "Bode";
  bode.x_scale = Scale::Log;
  bode.series.push_back({"g", {0.1, 1.0, 10.0}, {0.0, -3.0, -20.0}});
  b.charts.push_back(bode);
  doc.sections = {a, b};
  return doc;
}

TEST(Html, OneDocumentWithBalancedScriptsAndParsableData) {
  const Document doc = small_document();
  const std::string html = render(doc);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>\n", 0), 0u);
  EXPECT_EQ(count(html, "<!DOCTYPE"), 1u);
  EXPECT_EQ(count(html, "<html"), 1u);
  EXPECT_EQ(count(html, "</html>"), 1u);
  EXPECT_EQ(count(html, "<body>"), 1u);
  EXPECT_EQ(count(html, "</body>"), 1u);
  // Glue, library, data: every opened script element is closed exactly once.
  EXPECT_EQ(count(html, "<script"), 3u);
  EXPECT_EQ(count(html, "</script>"), 3u);
  EXPECT_EQ(count(html, "<style>"), 2u);
  EXPECT_EQ(count(html, "</style>"), 2u);
  EXPECT_EQ(count(html, "<section id=\"section-"), 2u);
  EXPECT_EQ(count(html, "<figure class=\"chart"), 3u);
  EXPECT_EQ(chart_count(doc), 3u);

  const nlohmann::json data = chart_data(html);
  EXPECT_EQ(data["format"], "servotwin.report-data/1");
  ASSERT_EQ(data["charts"].size(), 3u);
  EXPECT_EQ(data["charts"][0]["title"], "Line chart");
  EXPECT_EQ(data["charts"][0]["x_label"], "time [s]");
  EXPECT_EQ(data["charts"][0]["path"], false);
  EXPECT_EQ(data["charts"][1]["path"], true);
  EXPECT_EQ(data["charts"][2]["x_log"], true);
  const auto& b = data["charts"][0]["series"][1];
  EXPECT_EQ(b["label"], "b");
  EXPECT_EQ(b["samples"], 50);
  ASSERT_EQ(b["x"].size(), 50u);
  ASSERT_EQ(b["y"].size(), 50u);
  for (std::size_t k = 0; k < 50; ++k) {
    EXPECT_DOUBLE_EQ(b["x"][k].get<double>(), static_cast<double>(k) * 0.001);
    EXPECT_DOUBLE_EQ(b["y"][k].get<double>(), 2.0 * static_cast<double>(k));
  }
  // Text, tables, table of contents.
  EXPECT_NE(html.find("<p>One paragraph.</p>"), std::string::npos);
  EXPECT_NE(html.find("<p>Another one,<br>with a line break.</p>"), std::string::npos);
  EXPECT_NE(html.find("<caption>numbers</caption>"), std::string::npos);
  EXPECT_NE(html.find("<td>two</td><td>2</td>"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"#section-2\">Second</a>"), std::string::npos);
  // The embedded library and its license travel with the file.
  EXPECT_NE(html.find("uPlot"), std::string::npos);
  EXPECT_NE(html.find("MIT License"), std::string::npos);
}

TEST(Html, NumbersKeepNineSignificantDigits) {
  Document doc;
  Section s;
  Chart c;
  c.series.push_back({"v", {0.0, 1.0, 2.0, 3.0}, {1.0 / 3.0, 123456.789012, -2.5e-12, 0.1 + 0.2}});
  s.charts.push_back(c);
  doc.sections.push_back(s);
  const std::string text = data_text(render(doc));
  EXPECT_NE(text.find("[0.333333333,123456.789,-2.5e-12,0.3]"), std::string::npos) << text;
}

TEST(Html, HostileStringsAreEscapedEverywhere) {
  const std::string attack = "</script><script>alert(1)</script>";
  const std::string quotes = "say \"hi\" & 'bye' <b>";
  const std::string unicode = "Wei\xC3\x9F \xC2\xB5m \xC2\xB1 \xE2\x80\xA8 \xF0\x9F\x98\x80";  // ß µ ± U+2028 emoji
  Document doc;
  doc.title = attack;
  doc.subtitle = quotes;
  Section s;
  s.title = unicode;
  s.text = attack;
  s.tables.push_back({attack, {quotes}, {{attack}}});
  Chart c;
  c.title = attack;
  c.x_label = quotes;
  c.y_label = unicode;
  c.series.push_back({attack + "<!--", {0.0, 1.0}, {1.0, 2.0}});
  s.charts.push_back(c);
  doc.sections.push_back(s);
  const std::string html = render(doc);

  EXPECT_EQ(count(html, "<script"), 3u);
  EXPECT_EQ(count(html, "</script>"), 3u);
  EXPECT_EQ(html.find("alert(1)</script>"), std::string::npos);
  EXPECT_EQ(html.find("<b>"), std::string::npos);
  EXPECT_NE(html.find("<title>&lt;/script&gt;&lt;script&gt;alert(1)&lt;/script&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("say &quot;hi&quot; &amp; &#39;bye&#39; &lt;b&gt;"), std::string::npos);
  EXPECT_NE(html.find("Wei\xC3\x9F \xC2\xB5m"), std::string::npos);  // UTF-8 passes through

  const std::string text = data_text(html);
  EXPECT_EQ(text.find('<'), std::string::npos);
  EXPECT_EQ(text.find('>'), std::string::npos);
  const nlohmann::json data = nlohmann::json::parse(text);
  EXPECT_EQ(data["charts"][0]["title"], attack);
  EXPECT_EQ(data["charts"][0]["x_label"], quotes);
  EXPECT_EQ(data["charts"][0]["y_label"], unicode);
  EXPECT_EQ(data["charts"][0]["series"][0]["label"], attack + "<!--");
  // U+2028 is escaped (a line terminator for older JavaScript).
  EXPECT_NE(text.find("\\u2028"), std::string::npos);
}

TEST(Html, InvalidUtf8AndControlCharactersBecomeReplacementCharacters) {
  Document doc;
  doc.title = std::string("bad \xFF\xFE bytes \xC3 end");
  Section s;
  s.title = std::string("bell \x07 and overlong \xC0\xAF and surrogate \xED\xA0\x80");
  Chart c;
  c.title = doc.title;
  c.series.push_back({std::string("nul \0 inside", 12), {0.0, 1.0}, {0.0, 1.0}});
  s.charts.push_back(c);
  doc.sections.push_back(s);
  const std::string html = render(doc);
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_NE(html.find("<title>bad " + fffd + fffd + " bytes " + fffd + " end</title>"), std::string::npos);
  EXPECT_NE(html.find("bell " + fffd + " and overlong " + fffd + fffd + " and surrogate " + fffd + fffd + fffd),
            std::string::npos);
  const nlohmann::json data = chart_data(html);  // throws on invalid UTF-8
  EXPECT_EQ(data["charts"][0]["title"], "bad " + fffd + fffd + " bytes " + fffd + " end");
  EXPECT_EQ(data["charts"][0]["series"][0]["label"], std::string("nul \0 inside", 12));
}

TEST(Html, NonFiniteValuesBecomeNull) {
  Document doc;
  Section s;
  Chart line;
  line.series.push_back({"y", {0.0, 1.0, 2.0, 3.0, 4.0}, {1.0, kNaN, kInf, -kInf, 5.0}});
  s.charts.push_back(line);
  Chart path;
  path.equal_axes = true;
  path.series.push_back({"p", {0.0, kNaN, 2.0, 3.0}, {0.0, 1.0, -kInf, 3.0}});
  s.charts.push_back(path);
  doc.sections.push_back(s);
  const std::string text = data_text(render(doc));
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  const nlohmann::json data = nlohmann::json::parse(text);
  const auto& y = data["charts"][0]["series"][0]["y"];
  ASSERT_EQ(y.size(), 5u);
  EXPECT_EQ(y[0], 1.0);
  EXPECT_TRUE(y[1].is_null());
  EXPECT_TRUE(y[2].is_null());
  EXPECT_TRUE(y[3].is_null());
  EXPECT_EQ(y[4], 5.0);
  // A path point with any non-finite coordinate is null in both (a gap).
  const auto& p = data["charts"][1]["series"][0];
  ASSERT_EQ(p["x"].size(), 4u);
  EXPECT_TRUE(p["x"][1].is_null());
  EXPECT_TRUE(p["y"][1].is_null());
  EXPECT_TRUE(p["x"][2].is_null());
  EXPECT_TRUE(p["y"][2].is_null());
  EXPECT_EQ(p["x"][3], 3.0);
}

TEST(Html, PointsThatCannotBePlacedOnTheAxisAreLeftOut) {
  Document doc;
  Section s;
  Chart c;
  c.x_scale = Scale::Log;
  c.y_scale = Scale::Log;
  c.series.push_back({"g", {0.0, -1.0, kNaN, 1.0, 10.0, 100.0}, {1.0, 1.0, 1.0, 2.0, 0.0, -3.0}});
  s.charts.push_back(c);
  doc.sections.push_back(s);
  const nlohmann::json data = chart_data(render(doc));
  const auto& g = data["charts"][0]["series"][0];
  EXPECT_EQ(g["x"], nlohmann::json::parse("[1.0, 10.0, 100.0]"));
  // Non-positive values on a log y axis are gaps.
  EXPECT_EQ(g["y"], nlohmann::json::parse("[2.0, null, null]"));
  EXPECT_EQ(g["samples"], 6);
}

TEST(Html, LongSeriesAreDecimatedAndTheCaptionSaysSo) {
  Document doc;
  Section s;
  Chart c;
  c.title = "long";
  c.series.push_back(ramp("r", 100000));
  s.charts.push_back(c);
  doc.sections.push_back(s);
  HtmlOptions options;
  options.max_points = 1000;
  const std::string html = render(doc, options);
  const nlohmann::json data = chart_data(html);
  const auto& r = data["charts"][0]["series"][0];
  EXPECT_LE(r["x"].size(), 1000u);
  EXPECT_GE(r["x"].size(), 900u);
  EXPECT_EQ(r["x"].size(), r["y"].size());
  EXPECT_EQ(r["samples"], 100000);
  EXPECT_EQ(r["y"].front(), 0.0);
  EXPECT_EQ(r["y"].back(), 99999.0);
  EXPECT_NE(html.find("of 100\u202F000 points drawn"), std::string::npos);
}

// A 10-minute, 3-axis, 1 kHz capture: 600 000 samples in each of 3 series. Decimated to
// max_points = 4000 per series, each point is 2 numbers of at most 16 characters plus a comma:
// 3 x 4000 x 2 x 17 = 408 000 bytes of data, plus the embedded library and glue (measured below)
// and a few kB of page: well under 1 MB, where the raw data would be about 40 MB.
TEST(Html, TenMinuteThreeAxisDocumentStaysSmall) {
  constexpr std::size_t n = 600000;
  Document doc;
  Section s;
  Chart c;
  c.title = "tracking errors";
  for (int axis = 0; axis < 3; ++axis) {
    Series series{"axis " + std::to_string(axis), std::vector<double>(n), std::vector<double>(n)};
    for (std::size_t k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) * 1e-3;
      series.x[k] = t;
      series.y[k] = 0.01 * std::sin(2.0 * std::numbers::pi * (0.7 + axis) * t) + 1e-4 * std::sin(1.3e3 * t * (axis + 1));
    }
    c.series.push_back(std::move(series));
  }
  s.charts.push_back(c);
  doc.sections.push_back(s);
  const std::string empty_html = render(Document{});
  const std::string html = render(doc);
  EXPECT_LT(html.size(), empty_html.size() + 3 * 4000 * 2 * 17 + 4096);
  EXPECT_LT(html.size(), 1000000u);
  const nlohmann::json data = chart_data(html);
  for (const auto& one : data["charts"][0]["series"]) EXPECT_LE(one["y"].size(), 4000u);
}

TEST(Html, RejectsSeriesOfUnequalLengthNamingTheChart) {
  Document doc = small_document();
  doc.sections[0].charts[0].series[1].y.pop_back();
  try {
    render(doc);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "sections[0].charts[0].series[1]");
    EXPECT_NE(std::string(e.what()).find("Line chart"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("50 x but 49 y"), std::string::npos) << e.what();
  }
}

TEST(Html, RejectsDisplayBudgetsOutOfRange) {
  const Document doc = small_document();
  HtmlOptions options;
  options.max_points = kMinDisplayPoints - 1;
  EXPECT_THROW(render(doc, options), core::InputError);
  options = {};
  options.max_path_points = kMaxPathPoints + 1;
  EXPECT_THROW(render(doc, options), core::InputError);
}

TEST(Html, EmptyDocumentIsStillAPage) {
  const std::string html = render(Document{});
  EXPECT_EQ(count(html, "</script>"), 3u);
  EXPECT_EQ(chart_data(html)["charts"].size(), 0u);
  EXPECT_EQ(html.find("<nav"), std::string::npos);
}

}  // namespace html_test
}  // namespace
}  // namespace servotwin::report
