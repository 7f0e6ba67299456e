// report.html against metrics.json: every figure the page shows is the metric it names,
// read back from the HTML and checked without the report's own scale table: the number shown,
// divided by 100 where its unit is "%" (a fraction) and by 1 otherwise, is the stored value to the
// 4 significant digits the page prints; booleans are yes/no; strings are themselves. The unit shown
// is the one the key's suffix promises, and every key of metrics.json is shown somewhere.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "report/metric_names.h"
#include "report/report_html.h"
#include "tiny_case_support.h"

using namespace pneumo;
using nlohmann::json;
using testing_support::ScratchDir;

namespace {

bool ends_with(const std::string& s, const std::string& e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

std::string unescape(const std::string& s) {
  static const std::pair<const char*, char> kEntities[] = {
      {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&#39;", '\''}, {"&amp;", '&'}};
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    bool replaced = false;
    for (const auto& [entity, c] : kEntities)
      if (s.compare(i, std::string(entity).size(), entity) == 0) {
        out += c;
        i += std::string(entity).size();
        replaced = true;
        break;
      }
    if (!replaced) out += s[i++];
  }
  return out;
}

/// A cell's text: its markup (<b>, the timing bar's <div>) dropped, entities decoded.
std::string text_of(const std::string& html) {
  std::string t;
  bool in_tag = false;
  for (char c : html) {
    if (c == '<') in_tag = true;
    else if (c == '>') in_tag = false;
    else if (!in_tag) t += c;
  }
  return unescape(t);
}

struct Table {
  std::string kind;      // "metrics", "array", "timing", "landmarks", "landmark_errors", "other"
  std::string heading;   // the <h3> an array table is named by
  std::vector<std::vector<std::string>> rows;   // the header row first; cell text
};

/// Every <table> of the page, its rows split into cells. The page is written by one function in a
/// fixed shape (report_html.cpp), so plain string search reads it; a regex would choke on the
/// embedded images' base64.
std::vector<Table> tables_of(const std::string& html) {
  std::vector<Table> out;
  for (std::size_t at = html.find("<table"); at != std::string::npos; at = html.find("<table", at + 1)) {
    Table t;
    const std::size_t end = html.find("</table>", at);
    const std::size_t tag_end = html.find('>', at);
    const std::string tag = html.substr(at, tag_end - at + 1);
    const std::string before = html.substr(at >= 200 ? at - 200 : 0, at >= 200 ? 200 : at);
    if (tag == "<table class=\"metrics\">") t.kind = "metrics";
    else if (tag == "<table class=\"timing\">") t.kind = "timing";
    else if (tag == "<table class=\"landmark-errors\">") t.kind = "landmark_errors";
    else if (ends_with(before, "<h2>Landmarks</h2>\n")) t.kind = "landmarks";
    else if (ends_with(before, "</h3>\n")) {
      t.kind = "array";
      const std::size_t h = before.rfind("<h3>");
      t.heading = text_of(before.substr(h, before.rfind("</h3>") - h));
    } else t.kind = "other";
    const std::string body = html.substr(tag_end + 1, end - tag_end - 1);
    for (std::size_t r = body.find("<tr>"); r != std::string::npos; r = body.find("<tr>", r + 1)) {
      const std::string row = body.substr(r, body.find("</tr>", r) - r);
      std::vector<std::string> cells;
      for (std::size_t c = row.find("<t"); c != std::string::npos; c = row.find("<t", c + 1)) {
        if (row.compare(c, 3, "<td") != 0 && row.compare(c, 3, "<th") != 0) continue;
        const std::string close = row.compare(c, 3, "<td") == 0 ? "</td>" : "</th>";
        const std::size_t open_end = row.find('>', c);
        const std::size_t close_at = row.find(close, open_end);
        cells.push_back(text_of(row.substr(open_end + 1, close_at - open_end - 1)));
        c = close_at;
      }
      t.rows.push_back(cells);
    }
    out.push_back(t);
    at = end;
  }
  return out;
}

/// The unit a key promises by its last part's suffix, written here apart from metric_names.cpp so
/// that a wrong entry there cannot vouch for itself. "" where the key promises none.
std::string unit_promised(const std::string& key) {
  const std::string last = key.substr(key.rfind('.') + 1);   // npos + 1 == 0: the whole key
  if (ends_with(last, "_per_s")) return "/s";                // a rate: "Mvoxel/s" and the like
  static const std::pair<const char*, const char*> kWords[] = {
      {"mmhg", "mmHg"}, {"seconds", "s"}, {"fraction", "%"}, {"percent", "%"}, {"mm", "mm"}, {"ml", "ml"},
      {"ms", "ms"},     {"kpa", "kPa"},   {"pa", "Pa"},        {"deg", "°"},     {"s", "s"}};
  for (const auto& [word, unit] : kWords)
    if (last == word || ends_with(last, std::string("_") + word)) return unit;
  return "";
}

/// Checks that the unit shown for `key` is the one its suffix promises, and returns what divides
/// the shown number back to the stored one: 100 for a fraction shown in %, 1 otherwise.
double divisor_for(const std::string& where, const std::string& key, const std::string& unit) {
  const std::string promised = unit_promised(key);
  if (promised == "/s") {
    EXPECT_TRUE(ends_with(unit, "/s")) << where << ": " << key << " is a rate, shown in \"" << unit << "\"";
  } else if (!promised.empty()) {
    EXPECT_EQ(unit, promised) << where << ": " << key << "'s unit";
  } else {
    EXPECT_NE(unit, "%") << where << ": " << key << " is not a fraction, shown in %";
  }
  return unit == "%" && !ends_with(key, "_percent") ? 100.0 : 1.0;
}

bool parse_number(const std::string& s, double& d) {
  if (s.empty()) return false;
  char* end = nullptr;
  d = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

/// Whether `shown` is `stored` written to 4 significant digits (half a unit in the 4th digit of
/// the larger of the two, so 9.9996 shown as 10 passes and −673.8 shown as −0 does not).
bool agrees(double shown, double stored) {
  if (stored == 0.0) return shown == 0.0;
  const double magnitude = std::max(std::abs(shown), std::abs(stored));
  const double half_digit = 0.5 * std::pow(10.0, std::floor(std::log10(magnitude)) - 3);
  return std::abs(shown - stored) <= half_digit * (1 + 1e-9);
}

/// The shown value text (unit split off) against the stored value.
void expect_value(const std::string& where, const std::string& shown, const json& stored, double divisor) {
  if (stored.is_boolean()) {
    EXPECT_EQ(shown, stored.get<bool>() ? "yes" : "no") << where;
  } else if (stored.is_string()) {
    EXPECT_EQ(shown, stored.get<std::string>()) << where;
  } else if (stored.is_number()) {
    double d = 0;
    ASSERT_TRUE(parse_number(shown, d)) << where << ": \"" << shown << "\" is not a number";
    EXPECT_TRUE(agrees(d / divisor, stored.get<double>()))
        << where << ": shows " << shown << " (÷ " << divisor << "), metrics.json has " << stored.dump();
  } else if (stored.is_array() && !stored.empty() &&
             std::all_of(stored.begin(), stored.end(), [](const json& e) { return e.is_number(); })) {
    ASSERT_TRUE(shown.size() >= 2 && shown.front() == '[' && shown.back() == ']') << where << ": " << shown;
    std::vector<std::string> parts;
    const std::string inner = shown.substr(1, shown.size() - 2);
    for (std::size_t p = 0;;) {
      const std::size_t comma = inner.find(", ", p);
      parts.push_back(inner.substr(p, comma - p));
      if (comma == std::string::npos) break;
      p = comma + 2;
    }
    ASSERT_EQ(parts.size(), stored.size()) << where << ": " << shown;
    for (std::size_t i = 0; i < parts.size(); ++i)
      expect_value(where + "[" + std::to_string(i) + "]", parts[i], stored[i], divisor);
  } else {
    EXPECT_EQ(shown, stored.dump()) << where;
  }
}

/// A value cell ("−673.8 ml", "[1, 2, 3] mm", "yes", a string) split into value and unit by what
/// the stored value is: a string is all value, a number or a list of numbers is followed by its unit.
void split_cell(const std::string& cell, const json& stored, std::string& value, std::string& unit) {
  std::size_t end = std::string::npos;
  if (stored.is_number() || stored.is_boolean()) {
    end = cell.find(' ');
  } else if (stored.is_array() && !cell.empty() && cell.front() == '[') {
    end = cell.find("] ");
    if (end != std::string::npos) ++end;   // the space after the bracket
  }
  value = cell.substr(0, end);
  unit = end == std::string::npos ? "" : cell.substr(end + 1);
}

json::json_pointer pointer_of(const std::string& dotted) {
  std::string p = "/" + dotted;
  for (char& c : p)
    if (c == '.') c = '/';
  return json::json_pointer(p);
}

void expect_shown(const std::string& where, const std::string& key, const std::string& cell, const json& m) {
  const json::json_pointer p = pointer_of(key);
  ASSERT_TRUE(m.contains(p)) << where << ": the page shows " << key << ", which metrics.json does not hold";
  std::string value, unit;
  split_cell(cell, m.at(p), value, unit);
  const double divisor = divisor_for(where, key, unit);
  expect_value(where + " " + key, value, m.at(p), divisor);
}

/// Keys the metrics tables leave to sections of their own; checked there.
const std::set<std::string> kShownElsewhere = {"stage_seconds", "landmarks"};

/// The leaves of `obj` as dotted keys, and its arrays of objects (tables of their own).
void leaves_of(const json& obj, const std::string& prefix, std::vector<std::string>& leaves,
               std::vector<std::string>& arrays) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (prefix.empty() && kShownElsewhere.count(key)) continue;
    if (it->is_object()) leaves_of(*it, key, leaves, arrays);
    else if (it->is_array() && !it->empty() && it->front().is_object()) arrays.push_back(key);
    else leaves.push_back(key);
  }
}

/// The whole comparison: every figure on the page against metrics.json, and every key of
/// metrics.json on the page.
void expect_report_matches(const std::string& html, const json& m) {
  ASSERT_TRUE(m.is_object());
  const std::vector<Table> tables = tables_of(html);
  std::set<std::string> shown_keys;
  std::map<std::string, std::string> key_by_name;

  // The metrics tables: quantity, value with unit, key.
  for (const Table& t : tables) {
    if (t.kind != "metrics") continue;
    for (std::size_t r = 1; r < t.rows.size(); ++r) {
      const auto& row = t.rows[r];
      ASSERT_EQ(row.size(), 3u);
      const std::string& key = row[2];
      EXPECT_TRUE(shown_keys.insert(key).second) << key << " shown twice";
      EXPECT_TRUE(key_by_name.emplace(row[0], key).second)
          << "\"" << row[0] << "\" names both " << key_by_name[row[0]] << " and " << key;
      expect_shown("metrics table", key, row[1], m);
    }
  }

  // The arrays of objects: a table each, a column per key of the first object, named with its unit.
  std::vector<std::string> leaves, arrays;
  leaves_of(m, "", leaves, arrays);
  for (const std::string& key : arrays) {
    const json& arr = m.at(pointer_of(key));
    const std::string heading = metric_name(key).name;
    const Table* t = nullptr;
    for (const Table& c : tables)
      if (c.kind == "array" && c.heading == heading) t = &c;
    ASSERT_NE(t, nullptr) << key << ": no table headed \"" << heading << "\"";
    ASSERT_EQ(t->rows.size(), arr.size() + 1) << key;
    std::vector<std::string> columns;
    for (auto it = arr.front().begin(); it != arr.front().end(); ++it) columns.push_back(it.key());
    ASSERT_EQ(t->rows[0].size(), columns.size()) << key;
    for (const json& element : arr)
      for (auto it = element.begin(); it != element.end(); ++it)
        EXPECT_NE(std::find(columns.begin(), columns.end(), it.key()), columns.end())
            << key << ": " << it.key() << " has no column";
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::string& th = t->rows[0][c];
      const std::string promised = unit_promised(columns[c]);
      std::string unit;
      if (!promised.empty()) {
        EXPECT_TRUE(ends_with(th, " (" + promised + ")")) << key << "." << columns[c] << ": header \"" << th << "\"";
        unit = promised;
      } else {
        EXPECT_FALSE(ends_with(th, " (%)")) << key << "." << columns[c] << " is not a fraction, shown in %";
      }
      const double divisor = unit == "%" && !ends_with(columns[c], "_percent") ? 100.0 : 1.0;
      for (std::size_t r = 0; r < arr.size(); ++r) {
        const std::string where = key + "[" + std::to_string(r) + "]." + columns[c];
        const std::string& cell = t->rows[r + 1].at(c);
        if (!arr[r].contains(columns[c])) {
          EXPECT_EQ(cell, "") << where;
          continue;
        }
        expect_value(where, cell, arr[r].at(columns[c]), divisor);
      }
    }
  }

  // Every other key of metrics.json has its row.
  for (const std::string& key : leaves) EXPECT_TRUE(shown_keys.count(key)) << key << " is not on the page";

  // The summary: the outcome in words, and the cards (each the figure of a key the tables name).
  if (m.contains("converged")) {
    if (m["converged"] == true) {
      const std::size_t at = html.find("<p class=\"status ok\">Converged");
      ASSERT_NE(at, std::string::npos);
      const std::string status = text_of(html.substr(at, html.find("</p>", at) - at));
      if (m.contains("steps")) {
        const std::size_t s = status.find(" after ") + 7;
        expect_value("status: steps", status.substr(s, status.find(" solver steps") - s), m["steps"], 1.0);
      }
      if (m.contains("residual")) {
        const std::size_t s = status.find("final residual ") + 15;
        const std::size_t e = status.find(" of the pressure force");
        expect_value("status: residual", status.substr(s, e - s), m["residual"], 1.0);
      }
    } else {
      EXPECT_NE(html.find("<p class=\"status warn\">Not converged: " + m.value("stop_reason", std::string())),
                std::string::npos);
    }
  }
  const std::string card_open = "<div class=\"card\"><div class=\"v\">";
  for (std::size_t at = html.find(card_open); at != std::string::npos; at = html.find(card_open, at + 1)) {
    const std::size_t v = at + card_open.size();
    const std::string value_html = html.substr(v, html.find("</div>", v) - v);
    const std::size_t k = html.find("<div class=\"k\">", v) + 15;
    const std::string name = text_of(html.substr(k, html.find("</div>", k) - k));
    const std::string cell = text_of(value_html);
    if (name == "CT to report") {
      ASSERT_TRUE(ends_with(cell, " s")) << cell;
      expect_value("card: CT to report", cell.substr(0, cell.size() - 2), m.at("stage_seconds").at("total"), 1.0);
      continue;
    }
    ASSERT_TRUE(key_by_name.count(name)) << "the card \"" << name << "\" names no row of the metrics tables";
    expect_shown("card \"" + name + "\"", key_by_name[name], cell, m);
  }

  // Where the time went: a row a stage, in seconds.
  if (m.contains("stage_seconds") && !m["stage_seconds"].empty()) {
    const Table* t = nullptr;
    for (const Table& c : tables)
      if (c.kind == "timing") t = &c;
    ASSERT_NE(t, nullptr);
    ASSERT_EQ(t->rows[0].at(1), "seconds");
    std::set<std::string> stages;
    for (std::size_t r = 1; r < t->rows.size(); ++r) {
      const std::string& stage = t->rows[r].at(0);
      ASSERT_TRUE(m["stage_seconds"].contains(stage)) << stage;
      stages.insert(stage);
      expect_value("stage_seconds." + stage, t->rows[r].at(1), m["stage_seconds"][stage], 1.0);
    }
    for (auto it = m["stage_seconds"].begin(); it != m["stage_seconds"].end(); ++it)
      EXPECT_TRUE(stages.count(it.key())) << "stage_seconds." << it.key() << " is not on the page";
  }

  // Landmarks: a row a point; its columns by their headers.
  if (m.contains("landmarks") && m["landmarks"].contains("points") && !m["landmarks"]["points"].empty()) {
    const json& points = m["landmarks"]["points"];
    const Table* t = nullptr;
    for (const Table& c : tables)
      if (c.kind == "landmarks") t = &c;
    ASSERT_NE(t, nullptr);
    ASSERT_EQ(t->rows.size(), points.size() + 1);
    const std::map<std::string, std::string> key_of_header = {
        {"on the CT (mm)", "ct_mm"},
        {"simulated (mm)", "simulated_mm"},
        {"displacement (mm)", "displacement_mm"},
        {"|displacement| (mm)", "displacement_norm_mm"},
        {"measured after (mm)", "measured_after_ct_mm"},
        {"error (mm)", "error_mm"}};
    const auto& header = t->rows[0];
    ASSERT_EQ(header.at(0), "landmark");
    for (std::size_t r = 0; r < points.size(); ++r) {
      EXPECT_EQ(t->rows[r + 1].at(0), points[r].value("name", std::string()));
      for (std::size_t c = 1; c < header.size(); ++c) {
        ASSERT_TRUE(key_of_header.count(header[c])) << header[c];
        const std::string& key = key_of_header.at(header[c]);
        const std::string where = "landmarks.points[" + std::to_string(r) + "]." + key;
        if (points[r].contains(key)) expect_value(where, t->rows[r + 1].at(c), points[r][key], 1.0);
        else EXPECT_EQ(t->rows[r + 1].at(c), "") << where;
      }
    }
    // Measured: every summary figure against the CT after inflation, each in its own row, in mm.
    if (m["landmarks"].value("measured", false)) {
      const Table* e = nullptr;
      for (const Table& c : tables)
        if (c.kind == "landmark_errors") e = &c;
      ASSERT_NE(e, nullptr) << "the measured landmarks' summary is not on the page";
      const std::map<std::string, std::string> pointer_of_row = {
          {"Alignment of the two CTs (RMS)", "/landmarks/alignment_rms_mm"},
          {"Mean position error", "/landmarks/position_error_mm"},
          {"Mean displacement error, horizontal", "/landmarks/displacement_error_mm/horizontal"},
          {"Mean displacement error, ventrodorsal", "/landmarks/displacement_error_mm/ventrodorsal"},
          {"Mean displacement error, cephalocaudal", "/landmarks/displacement_error_mm/cephalocaudal"}};
      std::set<std::string> shown;
      for (std::size_t r = 1; r < e->rows.size(); ++r) {
        ASSERT_TRUE(pointer_of_row.count(e->rows[r].at(0))) << e->rows[r].at(0);
        const json::json_pointer at(pointer_of_row.at(e->rows[r].at(0)));
        expect_value(at.to_string(), e->rows[r].at(1), m.at(at), 1.0);
        shown.insert(at.to_string());
      }
      for (const auto& [row, pointer] : pointer_of_row) {
        if (m.contains(json::json_pointer(pointer))) {
          EXPECT_TRUE(shown.count(pointer)) << pointer << " is not on the page";
        }
      }
    }
  }
}

/// A value for `key` that no wrong scale, rounding or swap could still show as stored: non-round,
/// a different one each key, a fraction below 1, the types metrics.json gives these keys.
json distinctive_value(const std::string& key, int i) {
  static const std::set<std::string> kBooleans = {"converged", "pipeline_complete"};
  static const std::set<std::string> kStrings = {"solver", "device", "stop_reason", "pneumo_version",
                                                 "scene", "warp.device"};
  static const std::set<std::string> kCounts = {"steps", "force_evaluations", "inner_iterations", "nodes",
                                                "tetrahedra", "springs", "fixed_nodes", "cavity_voxels",
                                                "inverted_tetrahedra", "warp.carried_voxels", "render.views"};
  if (key == "viscera_volume_change_ml") return -673.8;   // once shown as "−0 ml"
  if (key == "render.deformed_ct") return false;
  if (kBooleans.count(key)) return true;
  if (kStrings.count(key)) return key + " <&> \"text\"";
  if (key == "warp.cavity_centroid_mm") return json::array({-12.34, 56.78, 901.2});
  if (key == "cube_edge_mm") return json::array({8.963, 9.012, 10.37});   // per axis, as simulate writes it
  if (key == "cube_voxels") return json::array({13, 12, 4});
  if (kCounts.count(key)) return 12 + 1237 * i;
  if (ends_with(key, "_fraction")) return 0.0371 + 0.0113 * i;
  return (i % 2 ? -1.0 : 1.0) * (1.234 + 7.919 * i);
}

}  // namespace

TEST(ReportMatchesMetrics, EveryFigureOfEveryKnownKeyIsItsMetric) {
  // Compared: a metrics.json with every key metric_names.cpp names (distinctive non-round values), keys
  // it does not name (named from their suffix), the pressure curve, the stage times and landmarks,
  // against the page report_html writes from it: each figure the page shows, read back from the HTML,
  // is the stored value to the 4 digits printed (÷ 100 in %), in the unit the key's suffix promises.
  json m = json::object();
  int i = 0;
  // Entries of an array's columns (pressure_curve.*, organ_motion.*) land in an object here; the arrays
  // set below replace them.
  for (const std::string& key : listed_metric_keys()) m[pointer_of(key)] = distinctive_value(key, i++);
  m["some_new_length_mm"] = 2.718;
  m["some_new_share_fraction"] = 0.0123;
  m["gravity_compensation"]["solves"] = 3;
  m["gravity_compensation"]["steps"] = 47;
  m["gravity_compensation"]["wall_time_s"] = 1.357;
  m["pressure_curve"] = json::array();
  for (int p = 0; p < 3; ++p)
    m["pressure_curve"].push_back({{"pressure_mmhg", 4.1 * (p + 1)},
                                   {"cavity_volume_ml", 123.4 + 456.7 * p},
                                   {"anterior_rise_mm", 9.876 + 3.21 * p},
                                   {"converged", p != 1},
                                   {"steps", 17 + p},
                                   {"residual", 0.000987 * (p + 1)},
                                   {"wall_time_s", 0.4321 * (p + 1)}});
  m["organ_motion"] = json::array();
  for (int o = 0; o < 2; ++o)
    m["organ_motion"].push_back({{"label", 5 + o},
                                 {"name", o ? "spleen" : "liver"},
                                 {"volume_ml", 1234.5 + 98.7 * o},
                                 {"volume_change_fraction", -0.0417 + 0.0123 * o},
                                 {"tissue_volume_change_fraction", -0.0389 + 0.0111 * o},
                                 {"shift_right_mm", 1.234 - o},
                                 {"shift_anterior_mm", -4.321 + o},
                                 {"shift_superior_mm", 2.468 + o}});
  m["stage_seconds"] = {{"roles", 0.1234}, {"mesh", 1.357}, {"solve", 24.68}, {"warp", 3.579},
                        {"render", 8.642}, {"report", 0.0975}, {"total", 38.52}};
  m["landmarks"] = {{"measured", true},
                    {"points",
                     {{{"name", "umbilicus"}, {"ct_mm", {1.5, 108.3, -20.7}}, {"simulated_mm", {1.6, 131.9, -21.4}},
                       {"displacement_mm", {0.1, 23.6, -0.7}}, {"displacement_norm_mm", 23.61},
                       {"measured_after_ct_mm", {1.2, 129.8, -22.6}}, {"error_mm", 2.345}},
                      {{"name", "L3"}, {"ct_mm", {0.3, -40.2, -60.9}}, {"simulated_mm", {0.3, -40.2, -60.9}},
                       {"displacement_mm", {0.0, 0.0, 0.0}}, {"displacement_norm_mm", 0.0},
                       {"measured_after_ct_mm", {0.7, -40.1, -61.2}}, {"error_mm", 0.4321}}}},
                    {"alignment_rms_mm", 0.8765},
                    {"position_error_mm", 1.3886},
                    {"displacement_error_mm", {{"horizontal", 0.3456}, {"ventrodorsal", 1.0987}, {"cephalocaudal", 0.6543}}}};
  ReportContent c;
  c.title = "every key";
  c.metrics = m;
  expect_report_matches(report_html(c), m);
}

TEST(ReportMatchesMetrics, TheCheckSeesAFigureThatIsNotItsMetric) {
  // Compared: the checks above against pages that lie, so that a check that passes everything does not
  // pass as coverage: a figure of the wrong size, a fraction not shown in %, a key left off.
  const json m = {{"viscera_volume_change_ml", -673.8}, {"cavity_outside_largest_piece_fraction", 0.0371}};
  ReportContent c;
  c.metrics = m;
  const std::string html = report_html(c);
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string h = html;
    const std::size_t at = h.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? h : h.replace(at, from.size(), to);
  };
  const std::string lying_pages[] = {
      replaced("<td>-673.8 ml</td>", "<td>-0 ml</td>"),
      replaced("<td>-673.8 ml</td>", "<td>-673.8 mm</td>"),
      replaced("<td>3.71 %</td>", "<td>0.0371 %</td>"),
      replaced("<td class=\"key\">viscera_volume_change_ml</td>", "<td class=\"key\">viscera_volume_change</td>")};
  for (const std::string& wrong : lying_pages) {
    testing::TestPartResultArray failures;
    {
      using Reporter = testing::ScopedFakeTestPartResultReporter;
      Reporter reporter(Reporter::INTERCEPT_ONLY_CURRENT_THREAD, &failures);
      expect_report_matches(wrong, m);
    }
    EXPECT_GT(failures.size(), 0) << "a lying page passed";
  }
}

TEST(ReportMatchesMetrics, ARealRunsReportIsItsMetricsJson) {
  // Compared: the same checks on the report and metrics.json `pneumo run` writes for the tiny case, with a
  // pressure-volume curve and landmarks so that their tables are on the page too.
  ScratchDir d;
  json scene = testing_support::tiny_case_scene_json();
  scene["load"]["pressure_curve_mmhg"] = {4, 8};
  scene["landmarks"] = {{{"name", "wall_middle"}, {"ct_mm", {-2.5, -2.5, 132.5}}},
                        {{"name", "back"}, {"ct_mm", {-2.5, -2.5, 102.5}}}};
  const std::string path = testing_support::write_tiny_case(d, scene);
  const auto r = testing_support::run_pneumo("-q run " + path + " --out " + d.file("run"));
  ASSERT_EQ(r.code, 0) << r.err;
  const json m = json::parse(testing_support::read_bytes(d.file("run/metrics.json")));
  ASSERT_TRUE(m.contains("pressure_curve"));
  ASSERT_TRUE(m.contains("landmarks"));
  // The mesh's size in the user's terms: the cube's edge per axis in mm and the
  // element count, both in metrics.json and so, by the check below, on the page.
  ASSERT_TRUE(m.contains("cube_edge_mm"));
  ASSERT_EQ(m["cube_edge_mm"].size(), 3u);
  for (const json& e : m["cube_edge_mm"]) EXPECT_GT(e.get<double>(), 0.0);
  EXPECT_GT(m["tetrahedra"].get<int64_t>(), 0);
  const std::string html = testing_support::read_bytes(d.file("run/report.html"));
  EXPECT_NE(html.find("Mesh cube edge per axis"), std::string::npos);
  EXPECT_NE(html.find("Tetrahedra (elements)"), std::string::npos);
  expect_report_matches(html, m);
}
