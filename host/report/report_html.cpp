#include "report/report_html.h"

#include "core/mime_type.h"
#include "report/markup.h"
#include "report/metric_names.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace pneumo {

namespace {

using nlohmann::json;

bool read_file(const std::string& path, std::string& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  bytes = ss.str();
  return bool(in) || in.eof();
}

std::string number(double d) {
  if (!std::isfinite(d)) return "non-finite";
  std::ostringstream os;
  os.precision(4);
  os << d;
  return os.str();
}

/// A JSON value as table text: numbers (× scale) to 4 significant digits, true/false as yes/no,
/// arrays of numbers as [a, b, c], other arrays and objects compact.
std::string cell(const json& v, double scale = 1.0) {
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer() && scale == 1.0) return v.dump();
  if (v.is_number()) return number(v.get<double>() * scale);
  if (v.is_string()) return v.get<std::string>();
  if (v.is_array() && std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_number(); })) {
    std::string s = "[";
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + number(v[i].get<double>() * scale);
    return s + "]";
  }
  return v.dump();
}

std::string with_unit(const json& v, const MetricName& n) {
  return cell(v, n.scale) + (n.unit.empty() ? "" : (n.unit == "%" ? " %" : " " + n.unit));
}

std::string img_tag(const std::string& path, const std::string& alt) {
  std::string bytes;
  if (!read_file(path, bytes) || bytes.empty()) return "<p class=\"warn\">missing: " + escape_markup(path) + "</p>";
  return "<img alt=\"" + escape_markup(alt) + "\" src=\"data:" + mime_type_of(path) + ";base64," + base64(bytes) + "\">";
}

void figure(const ReportImage& im, std::ostringstream& o) {
  o << "<figure>" << img_tag(im.path, im.title) << "<figcaption><b>" << escape_markup(im.title) << "</b>";
  if (!im.caption.empty()) o << " " << escape_markup(im.caption);
  o << "</figcaption></figure>\n";
}

// Keys shown elsewhere on the page, not in the metrics table.
const std::set<std::string> kNotInTable = {"stage_seconds", "landmarks"};

struct Row {
  std::string key;
  const json* value;
};

/// Leaves of `obj` as "parent.child" keys; arrays of objects are tables of their own.
void leaves(const json& obj, const std::string& prefix, std::vector<Row>& out, std::vector<Row>& tables) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (prefix.empty() && kNotInTable.count(key)) continue;
    if (it->is_object()) {
      leaves(*it, key, out, tables);
    } else if (it->is_array() && !it->empty() && it->front().is_object()) {
      tables.push_back({key, &*it});
    } else {
      out.push_back({key, &*it});
    }
  }
}

/// An array of objects as a table, the first object's keys as columns, named with units.
void array_table(const std::string& key, const json& arr, std::ostringstream& o) {
  o << "<table><tr>";
  for (auto it = arr.front().begin(); it != arr.front().end(); ++it) {
    const MetricName n = column_name(key, it.key());
    o << "<th>" << escape_markup(n.name) << (n.unit.empty() ? "" : " (" + escape_markup(n.unit) + ")") << "</th>";
  }
  o << "</tr>\n";
  for (const auto& row : arr) {
    o << "<tr>";
    for (auto it = arr.front().begin(); it != arr.front().end(); ++it) {
      const double scale = column_name(key, it.key()).scale;
      o << "<td>" << (row.contains(it.key()) ? escape_markup(cell(row.at(it.key()), scale)) : "") << "</td>";
    }
    o << "</tr>\n";
  }
  o << "</table>\n";
}

/// What the CT covers (metrics.json "scan_coverage"), with what it misses in red.
void coverage(const json& m, std::ostringstream& o) {
  if (!m.is_object() || !m.contains("scan_coverage")) return;
  const json& c = m["scan_coverage"];
  if (!c.is_object()) return;
  if (c.contains("summary") && c["summary"].is_string()) o << "<p>" << escape_markup(c["summary"].get<std::string>()) << "</p>\n";
  if (c.contains("warnings") && c["warnings"].is_array() && !c["warnings"].empty()) {
    o << "<ul class=\"warn\">";
    for (const json& w : c["warnings"]) o << "<li>" << escape_markup(w.is_string() ? w.get<std::string>() : w.dump()) << "</li>";
    o << "</ul>\n";
  }
}

void summary(const json& m, std::ostringstream& o) {
  if (!m.is_object()) return;
  if (m.contains("converged")) {
    const bool ok = m["converged"].is_boolean() && m["converged"].get<bool>();
    o << "<p class=\"status " << (ok ? "ok" : "warn") << "\">";
    if (ok) {
      o << "Converged";
      if (m.contains("steps")) o << " after " << escape_markup(cell(m["steps"])) << " solver steps";
      if (m.contains("residual"))
        o << "; final residual " << escape_markup(cell(m["residual"])) << " of the pressure force";
      o << ".";
    } else {
      o << "Not converged: " << escape_markup(m.value("stop_reason", std::string("unknown reason")))
        << ". The shape shown is the solver's last state; read the numbers with care.";
    }
    o << "</p>\n";
  }
  o << "<div class=\"cards\">\n";
  for (const char* key : {"anterior_rise_mm", "cavity_volume_ml", "pressure_mmhg", "mean_viscera_displacement_mm",
                          "inverted_tetrahedra"}) {
    if (!m.contains(key)) continue;
    const MetricName n = metric_name(key);
    o << "<div class=\"card\"><div class=\"v\">" << escape_markup(with_unit(m[key], n)) << "</div><div class=\"k\">"
      << escape_markup(n.name) << "</div></div>\n";
  }
  if (m.contains("stage_seconds") && m["stage_seconds"].contains("total"))
    o << "<div class=\"card\"><div class=\"v\">" << escape_markup(cell(m["stage_seconds"]["total"])) << " s</div>"
      << "<div class=\"k\">CT to report</div></div>\n";
  o << "</div>\n";
}

void animation(const ReportAnimation& a, int index, std::ostringstream& o) {
  std::string bytes;
  o << "<figure class=\"fly\">";
  if (!read_file(a.strip_path, bytes) || bytes.empty() || a.frames <= 0 || a.frame_width <= 0) {
    o << "<p class=\"warn\">missing: " << escape_markup(a.strip_path) << "</p></figure>\n";
    return;
  }
  // Shown at twice the strip's frame size; steps(N) jumps frame by frame from 0 to −(N−1)·w.
  const int w = 2 * a.frame_width, h = 2 * a.frame_height, n = a.frames;
  const std::string cls = "strip" + std::to_string(index);
  o << "<style>." << cls << "{background-image:url(data:" << mime_type_of(a.strip_path) << ";base64," << base64(bytes)
    << ");background-repeat:no-repeat}@keyframes play" << index << "{from{background-position:0 0}to{background-position:-"
    << int64_t(n) * w << "px 0}}</style>\n";
  o << "<div class=\"" << cls << " player\" role=\"img\" aria-label=\"" << escape_markup(a.title) << "\" style=\"width:" << w
    << "px;height:" << h << "px;background-size:" << int64_t(n) * w << "px " << h << "px;animation:play" << index << " "
    << number(n / std::max(a.fps, 1e-3)) << "s steps(" << n << ") infinite\"></div>\n";
  o << "<div class=\"filmstrip\"><div class=\"" << cls << "\" style=\"width:" << int64_t(n) * a.frame_width / 2
    << "px;height:" << a.frame_height / 2 << "px;background-size:" << int64_t(n) * a.frame_width / 2 << "px "
    << a.frame_height / 2 << "px\"></div></div>\n";
  o << "<figcaption><b>" << escape_markup(a.title) << "</b> " << escape_markup(a.caption);
  if (!a.video_link.empty())
    o << " Full size: <a href=\"" << escape_markup(a.video_link) << "\">" << escape_markup(a.video_link) << "</a>.";
  o << "</figcaption></figure>\n";
}

void timings(const json& stages, std::ostringstream& o) {
  if (!stages.is_object() || stages.empty()) return;
  std::vector<std::string> keys;
  for (const std::string& k : pipeline_stage_order())
    if (stages.contains(k) && k != "total") keys.push_back(k);
  for (auto it = stages.begin(); it != stages.end(); ++it)
    if (std::find(keys.begin(), keys.end(), it.key()) == keys.end() && it.key() != "total") keys.push_back(it.key());
  double total = stages.value("total", 0.0);
  if (!(total > 0)) for (const auto& k : keys) total += stages[k].get<double>();
  o << "<h2>Where the time went</h2>\n<table class=\"timing\"><tr><th>stage</th><th>seconds</th><th></th></tr>\n";
  for (const std::string& k : keys) {
    const double s = stages[k].is_number() ? stages[k].get<double>() : 0.0;
    const double pct = total > 0 ? std::clamp(100.0 * s / total, 0.0, 100.0) : 0.0;
    o << "<tr><td>" << escape_markup(k) << "</td><td>" << number(s) << "</td><td><div class=\"bar\" style=\"width:"
      << number(pct) << "%\"></div></td></tr>\n";
  }
  if (stages.contains("total"))
    o << "<tr><td><b>total</b></td><td><b>" << escape_markup(cell(stages["total"])) << "</b></td><td></td></tr>\n";
  o << "</table>\n<p class=\"note\">In pipeline order; the stages run one after another, and the total also "
       "counts reading the inputs and writing the outputs.</p>\n";
}

void landmarks(const json& m, std::ostringstream& o) {
  if (!m.contains("landmarks") || !m["landmarks"].contains("points")) return;
  const json& pts = m["landmarks"]["points"];
  if (!pts.is_array() || pts.empty()) return;
  const bool measured = m["landmarks"].value("measured", false);
  o << "<h2>Landmarks</h2>\n<table><tr><th>landmark</th><th>on the CT (mm)</th><th>simulated (mm)</th>"
       "<th>displacement (mm)</th><th>|displacement| (mm)</th>"
    << (measured ? "<th>measured after (mm)</th><th>error (mm)</th>" : "") << "</tr>\n";
  for (const json& p : pts) {
    o << "<tr><td>" << escape_markup(p.value("name", std::string())) << "</td>";
    for (const char* k : {"ct_mm", "simulated_mm", "displacement_mm", "displacement_norm_mm"})
      o << "<td>" << (p.contains(k) ? escape_markup(cell(p[k])) : "") << "</td>";
    if (measured)
      for (const char* k : {"measured_after_ct_mm", "error_mm"})
        o << "<td>" << (p.contains(k) ? escape_markup(cell(p[k])) : "") << "</td>";
    o << "</tr>\n";
  }
  o << "</table>\n";
  if (!measured) return;
  // The summary against the CT taken after inflation: how well the two CTs were aligned (rigidly, on the
  // landmarks that do not move), and the simulation's mean errors.
  const json& l = m["landmarks"];
  const std::pair<const char*, json> summary[] = {
      {"Alignment of the two CTs (RMS)", l.value("alignment_rms_mm", json())},
      {"Mean position error", l.value("position_error_mm", json())},
      {"Mean displacement error, horizontal", l.contains("displacement_error_mm") ? l["displacement_error_mm"].value("horizontal", json()) : json()},
      {"Mean displacement error, ventrodorsal", l.contains("displacement_error_mm") ? l["displacement_error_mm"].value("ventrodorsal", json()) : json()},
      {"Mean displacement error, cephalocaudal", l.contains("displacement_error_mm") ? l["displacement_error_mm"].value("cephalocaudal", json()) : json()}};
  o << "<table class=\"landmark-errors\"><tr><th>against the CT after inflation</th><th>mm</th></tr>\n";
  for (const auto& [name, value] : summary)
    if (!value.is_null()) o << "<tr><td>" << name << "</td><td>" << escape_markup(cell(value)) << "</td></tr>\n";
  o << "</table>\n";
}

void metrics_tables(const json& m, std::ostringstream& o) {
  if (!m.is_object()) return;
  std::vector<Row> rows, tables;
  leaves(m, "", rows, tables);
  o << "<h2>Metrics</h2>\n";
  for (const std::string& group : metric_groups()) {
    std::vector<std::pair<MetricName, const Row*>> in;
    for (const Row& r : rows) {
      const MetricName n = metric_name(r.key);
      if (n.group == group) in.push_back({n, &r});
    }
    if (in.empty()) continue;
    o << "<h3>" << escape_markup(group) << "</h3>\n<table class=\"metrics\"><tr><th>quantity</th><th>value</th>"
         "<th>metrics.json key</th></tr>\n";
    for (const auto& [n, r] : in)
      o << "<tr><td>" << escape_markup(n.name) << "</td><td>" << escape_markup(with_unit(*r->value, n))
        << "</td><td class=\"key\">" << escape_markup(r->key) << "</td></tr>\n";
    o << "</table>\n";
  }
  for (const Row& t : tables) {
    const MetricName n = metric_name(t.key);
    o << "<h3>" << escape_markup(n.name) << "</h3>\n";
    array_table(t.key, *t.value, o);
  }
}

void scene_rows(const json& obj, const std::string& prefix, std::ostringstream& o) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object()) {
      scene_rows(*it, key, o);
      continue;
    }
    o << "<tr><td>" << escape_markup(key) << "</td><td>" << escape_markup(cell(*it)) << "</td></tr>\n";
  }
}

}  // namespace

std::string base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 | uint8_t(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += table[(v >> s) & 63];
  }
  if (i < bytes.size()) {
    uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string report_html(const ReportContent& c) {
  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" << escape_markup(c.title)
    << "</title>\n<style>\n"
       "body{font-family:sans-serif;margin:2em auto;max-width:1100px;color:#222;padding:0 1em}\n"
       "h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}\n"
       "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ddd;padding:2px 8px;text-align:left;"
       "font-size:.9em}th{background:#f3f3f3}td.key{color:#888;font-family:monospace;font-size:.8em}\n"
       "figure{display:inline-block;margin:.5em;vertical-align:top;max-width:100%}"
       "figcaption{font-size:.9em;color:#444;max-width:520px}\n"
       "img{max-width:100%;border:1px solid #ccc}.warn{color:#b00}.ok{color:#060}.status{font-size:1.1em}\n"
       ".cards{display:flex;flex-wrap:wrap;gap:.8em;margin:1em 0}.card{border:1px solid #ccc;border-radius:6px;"
       "padding:.5em 1em;min-width:9em}.card .v{font-size:1.5em;font-weight:bold}.card .k{font-size:.85em;color:#555}\n"
       ".player{border:1px solid #ccc}.filmstrip{overflow-x:auto;max-width:1060px;margin-top:.3em}\n"
       ".timing td:nth-child(3){width:420px}.bar{background:#5b8db8;height:.9em}.note{font-size:.85em;color:#555}\n"
       "details{margin-top:1.6em}summary{cursor:pointer;font-size:1.2em;font-weight:bold}\n"
       "</style></head><body>\n";
  o << "<h1>" << escape_markup(c.title) << "</h1>\n";
  if (!c.description.empty()) o << "<p>" << escape_markup(c.description) << "</p>\n";
  summary(c.metrics, o);
  coverage(c.metrics, o);
  if (!c.views.empty()) {
    o << "<h2>Views</h2>\n";
    for (const ReportImage& v : c.views) figure(v, o);
  }
  if (!c.flythroughs.empty()) {
    o << "<h2>Fly-through</h2>\n";
    for (std::size_t i = 0; i < c.flythroughs.size(); ++i) animation(c.flythroughs[i], int(i), o);
  }
  if (!c.images.empty()) {
    o << "<h2>Before and after</h2>\n";
    for (const ReportImage& im : c.images) figure(im, o);
  }
  if (!c.plots.empty()) {
    o << "<h2>Solver</h2>\n";
    for (const auto& p : c.plots) {
      const std::size_t at = p.svg.find("<svg");
      o << "<figure>" << (at == std::string::npos ? "" : p.svg.substr(at)) << "<figcaption><b>" << escape_markup(p.title)
        << "</b></figcaption></figure>\n";
    }
  }
  if (c.metrics.is_object() && c.metrics.contains("stage_seconds")) timings(c.metrics["stage_seconds"], o);
  landmarks(c.metrics, o);
  metrics_tables(c.metrics, o);
  if (c.scene.is_object()) {
    o << "<details><summary>Scene: every parameter, defaults included</summary>\n<table>\n";
    scene_rows(c.scene, "", o);
    o << "</table>\n</details>\n";
  }
  o << "<p style=\"color:#888;font-size:.8em\">pneumo " << PNEUMO_VERSION << "</p>\n</body></html>\n";
  return o.str();
}

}  // namespace pneumo
