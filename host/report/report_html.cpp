#include "report/report_html.h"
#include "report/markup.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace pneumo {

namespace {

bool read_file(const std::string& path, std::string& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  bytes = ss.str();
  return bool(in) || in.eof();
}

/// A JSON value as table text: numbers to 4 significant digits, arrays and objects compact.
std::string cell(const nlohmann::json& v) {
  if (v.is_number_float()) {
    const double d = v.get<double>();
    if (!std::isfinite(d)) return "non-finite";
    std::ostringstream os;
    os.precision(4);
    os << d;
    return os.str();
  }
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

/// Rows "key | value" of an object; nested objects become "parent.key".
void rows(const nlohmann::json& obj, const std::string& prefix, std::ostringstream& o) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object()) {
      rows(*it, key, o);
      continue;
    }
    if (it->is_array() && !it->empty() && it->front().is_object()) continue;   // tables of their own
    o << "<tr><td>" << escape_markup(key) << "</td><td>" << escape_markup(cell(*it)) << "</td></tr>\n";
  }
}

/// An array of objects as a table, the first object's keys as columns.
void array_table(const nlohmann::json& arr, std::ostringstream& o) {
  if (!arr.is_array() || arr.empty() || !arr.front().is_object()) return;
  o << "<table><tr>";
  for (auto it = arr.front().begin(); it != arr.front().end(); ++it) o << "<th>" << escape_markup(it.key()) << "</th>";
  o << "</tr>\n";
  for (const auto& row : arr) {
    o << "<tr>";
    for (auto it = arr.front().begin(); it != arr.front().end(); ++it)
      o << "<td>" << escape_markup(row.contains(it.key()) ? cell(row.at(it.key())) : "") << "</td>";
    o << "</tr>\n";
  }
  o << "</table>\n";
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
       "body{font-family:sans-serif;margin:2em auto;max-width:1100px;color:#222}\n"
       "h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}\n"
       "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ddd;padding:2px 8px;text-align:left;"
       "font-size:.9em}th{background:#f3f3f3}\n"
       "figure{display:inline-block;margin:.5em;vertical-align:top}figcaption{font-size:.9em;color:#555}\n"
       "img{max-width:100%;border:1px solid #ccc}.warn{color:#b00}\n"
       "</style></head><body>\n";
  o << "<h1>" << escape_markup(c.title) << "</h1>\n";
  const nlohmann::json& m = c.metrics;
  if (m.is_object()) {
    o << "<p>";
    if (m.contains("converged"))
      o << (m["converged"].get<bool>() ? "Converged" : "<span class=\"warn\">Not converged</span>") << " ("
        << escape_markup(cell(m.value("stop_reason", nlohmann::json("")))) << "). ";
    for (const char* key : {"anterior_rise_mm", "cavity_volume_ml", "inverted_tetrahedra", "pressure_mmhg"})
      if (m.contains(key)) o << escape_markup(key) << ": <b>" << escape_markup(cell(m[key])) << "</b>. ";
    o << "</p>\n";
  }
  if (m.contains("stage_seconds")) {
    o << "<h2>Timings</h2>\n<table><tr><th>stage</th><th>seconds</th></tr>\n";
    for (auto it = m["stage_seconds"].begin(); it != m["stage_seconds"].end(); ++it)
      o << "<tr><td>" << escape_markup(it.key()) << "</td><td>" << escape_markup(cell(*it)) << "</td></tr>\n";
    o << "</table>\n";
  }
  if (!c.plots.empty()) {
    o << "<h2>Plots</h2>\n";
    for (const auto& p : c.plots) {
      const std::size_t at = p.svg.find("<svg");
      o << "<figure>" << (at == std::string::npos ? "" : p.svg.substr(at)) << "<figcaption>" << escape_markup(p.title)
        << "</figcaption></figure>\n";
    }
  }
  if (!c.images.empty()) {
    o << "<h2>Images</h2>\n";
    for (const auto& img : c.images) {
      std::string bytes;
      o << "<figure>";
      if (read_file(img.path, bytes) && !bytes.empty())
        o << "<img alt=\"" << escape_markup(img.title) << "\" src=\"data:image/png;base64," << base64(bytes) << "\">";
      else
        o << "<p class=\"warn\">missing: " << escape_markup(img.path) << "</p>";
      o << "<figcaption>" << escape_markup(img.title) << "</figcaption></figure>\n";
    }
  }
  if (m.is_object()) {
    o << "<h2>Metrics</h2>\n<table>\n";
    rows(m, "", o);
    o << "</table>\n";
    for (auto it = m.begin(); it != m.end(); ++it)
      if (it->is_array() && !it->empty() && it->front().is_object()) {
        o << "<h3>" << escape_markup(it.key()) << "</h3>\n";
        array_table(*it, o);
      }
  }
  if (c.scene.is_object()) {
    o << "<h2>Scene (every parameter, defaults included)</h2>\n<table>\n";
    rows(c.scene, "", o);
    o << "</table>\n";
  }
  o << "<p style=\"color:#888;font-size:.8em\">pneumo " << PNEUMO_VERSION << "</p>\n</body></html>\n";
  return o.str();
}

}  // namespace pneumo
