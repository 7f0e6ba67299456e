// Reading one JSON value against its ParamInfo, and the wording of every message and of the
// "allowed" column: one place, so the reference and the errors always say the same thing.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>
#include <utility>

#include "core/error.h"
#include "scene/param_table.h"
#include "scene/scene_json.h"

namespace pneumo::scene_detail {
namespace {

// Integers as integers ("65535", not "65535.0"); everything else in JSON's shortest form.
std::string number_text(double x) {
  if (std::isfinite(x) && x == std::floor(x) && std::fabs(x) < 1e15)
    return std::to_string(static_cast<long long>(x));
  return json(x).dump();
}

std::string lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// How far a typed name is from a known one; kFar when it is not worth suggesting. A name that is
// the other plus a suffix ("pressure" → "pressure_mmhg", "newmark-beta" → "newmark") counts as
// very close: leaving out a unit, or adding a qualifier, are the likeliest slips.
constexpr std::size_t kFar = static_cast<std::size_t>(-1);
std::size_t closeness(const std::string& typed, const std::string& known) {
  const std::string t = lower(typed), k = lower(known);
  if (t == k) return 0;
  const auto extends = [](const std::string& longer, const std::string& shorter) {
    return longer.size() > shorter.size() && longer.compare(0, shorter.size(), shorter) == 0 &&
           (longer[shorter.size()] == '_' || longer[shorter.size()] == '-');
  };
  if (extends(k, t) || extends(t, k)) return 1;
  const std::size_t d = edit_distance(t, k);
  return d <= std::max<std::size_t>(2, t.size() / 4) ? d : kFar;
}

// Every key of the tree, as (name, generic full path): "render.cameras[].fov_deg".
void collect_keys(const TableDoc& t, const std::string& prefix,
                  std::vector<std::pair<std::string, std::string>>& out) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    const ParamInfo& p = t.info(i);
    const std::string full = prefix.empty() ? p.key : prefix + "." + p.key;
    out.emplace_back(p.key, full);
    if (p.sub) collect_keys(*p.sub, p.kind == Kind::ObjectArray ? full + "[]" : full, out);
  }
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "\"" : ", \"") + n + "\"";
  return s;
}

[[noreturn]] void fail_type(const json& v, const ParamInfo& p, const At& at) {
  at.fail_value(v, "has the wrong type; expected " + p.expected_text());
}

[[noreturn]] void fail_range(const json& v, const ParamInfo& p, const At& at) {
  at.fail_value(v, "is out of range; allowed: " + p.c.range.text() + (p.unit.empty() ? "" : " " + p.unit));
}

// A number (finite; JSON cannot spell inf or nan, but 1e999 parses as inf) within the range.
double checked_number(const json& v, const ParamInfo& p, const At& at) {
  if (!v.is_number()) fail_type(v, p, at);
  const double x = v.get<double>();
  if (!std::isfinite(x)) at.fail_value(v, "is not a finite number");
  if (!p.c.range.contains(x)) fail_range(v, p, at);
  return x;
}

// An element of a list, for its messages: same range and unit, its own type.
ParamInfo element_info(const ParamInfo& list, Kind kind) {
  ParamInfo e = list;
  e.kind = kind;
  e.optional = false;
  return e;
}

}  // namespace

// ---- ranges and constraints --------------------------------------------------------------------

bool Range::contains(double x) const {
  const bool lo_ok = lo_open ? x > lo : x >= lo;
  const bool hi_ok = hi_open ? x < hi : x <= hi;
  return lo_ok && hi_ok;
}

std::string Range::text() const {
  const bool has_lo = lo > -kInf, has_hi = hi < kInf;
  const std::string l = (lo_open ? "> " : ">= ") + number_text(lo);
  const std::string h = (hi_open ? "< " : "<= ") + number_text(hi);
  if (has_lo && has_hi && lo == hi) return number_text(lo);
  if (has_lo && has_hi && !lo_open && !hi_open) return number_text(lo) + " to " + number_text(hi);
  if (has_lo && has_hi) return l + " and " + h;
  if (has_lo) return l;
  if (has_hi) return h;
  return "any";
}

Constraint Constraint::items(std::size_t lo, std::size_t hi) const {
  Constraint c = *this;
  c.min_items = lo;
  c.max_items = hi;
  return c;
}
Constraint Constraint::rule(const char* text, bool (*ok)(const json&)) const {
  Constraint c = *this;
  c.rule_text = text;
  c.rule_ok = ok;
  return c;
}
Constraint Constraint::req() const {
  Constraint c = *this;
  c.required = true;
  return c;
}

Constraint any() { return {}; }
Constraint in(double lo, double hi) {
  Constraint c;
  c.range = {lo, hi, false, false};
  return c;
}
Constraint above(double lo, double hi) {
  Constraint c;
  c.range = {lo, hi, true, false};
  return c;
}
Constraint at_least(double lo) { return in(lo, kInf); }
Constraint required() { return any().req(); }
Constraint file_path() {
  Constraint c;
  c.is_path = true;
  return c;
}

// ---- words -------------------------------------------------------------------------------------

std::string ParamInfo::type_text() const {
  switch (kind) {
    case Kind::Bool: return "bool";
    case Kind::Int: return "integer";
    case Kind::Real: return "number";
    case Kind::String: return "string";
    case Kind::Path: return "path";
    case Kind::Enum: return "enum";
    case Kind::Vec3: return "[x, y, z]";
    case Kind::IdList: return "array of integers";
    case Kind::RealList: return "array of numbers";
    case Kind::Section: return "object";
    case Kind::ObjectArray: return "array of objects";
    case Kind::CubeVoxels: return "integer or [i, j, k]";
  }
  return "?";
}

std::string ParamInfo::expected_text() const {
  std::string s;
  switch (kind) {
    case Kind::Bool: s = "true or false"; break;
    case Kind::Int: s = "an integer"; break;
    case Kind::Real: s = "a number"; break;
    case Kind::String: s = "a string"; break;
    case Kind::Path: s = "a path (string)"; break;
    case Kind::Enum: s = "one of " + quoted_list(choices); break;
    case Kind::Vec3: s = "an array of 3 numbers"; break;
    case Kind::IdList: s = "an array of integers"; break;
    case Kind::RealList: s = "an array of numbers"; break;
    case Kind::Section: s = "an object"; break;
    case Kind::ObjectArray: s = "an array of objects"; break;
    case Kind::CubeVoxels: s = "an integer or an array of 3 integers"; break;
  }
  return optional ? s + " or null" : s;
}

std::string ParamInfo::allowed_text() const {
  std::vector<std::string> parts;
  const auto items = [&]() -> std::string {
    if (c.min_items == 0 && c.max_items == kNoLimit) return "";
    if (c.max_items == kNoLimit) return std::to_string(c.min_items) + " or more items";
    if (c.min_items == 0) return "at most " + std::to_string(c.max_items) + " items";
    return std::to_string(c.min_items) + " to " + std::to_string(c.max_items) + " items";
  };
  switch (kind) {
    case Kind::Bool: parts.push_back("true, false"); break;
    case Kind::Int:
    case Kind::Real: parts.push_back(c.range.text()); break;
    case Kind::String: break;
    case Kind::Path: parts.push_back("relative to the scene's folder, or absolute"); break;
    case Kind::Enum: parts.push_back(quoted_list(choices)); break;
    case Kind::Vec3: parts.push_back(c.range.text() == "any" ? "finite" : "each " + c.range.text()); break;
    case Kind::IdList: parts.push_back("each " + c.range.text() + ", no repeats"); break;
    case Kind::RealList: parts.push_back("each " + c.range.text()); break;
    case Kind::Section: break;
    case Kind::ObjectArray: break;
    case Kind::CubeVoxels: parts.push_back("each " + c.range.text()); break;
  }
  if (!items().empty()) parts.push_back(items());
  if (c.rule_text) parts.push_back(c.rule_text);
  std::string s;
  for (const std::string& part : parts) s += (s.empty() ? "" : "; ") + part;
  return s.empty() ? "any" : s;
}

std::string show(const json& value) {
  std::string s = value.dump();
  constexpr std::size_t kMax = 80;
  if (s.size() > kMax) s = s.substr(0, kMax - 3) + "...";
  return s;
}

// ---- where -------------------------------------------------------------------------------------

At At::child(const std::string& key) const { return {ctx, path.empty() ? key : path + "." + key}; }
At At::item(std::size_t i) const { return {ctx, path + "[" + std::to_string(i) + "]"}; }

void At::fail(const std::string& problem) const {
  throw InputError(ctx->file + ": " + (path.empty() ? "the scene" : path) + " " + problem);
}
void At::fail_value(const json& value, const std::string& problem) const {
  fail("= " + show(value) + " " + problem);
}

const ParamInfo* TableDoc::find(const std::string& key) const {
  for (std::size_t i = 0; i < size(); ++i)
    if (info(i).key == key) return &info(i);
  return nullptr;
}

// ---- values ------------------------------------------------------------------------------------

bool read_bool(const json& v, const ParamInfo& p, const At& at) {
  if (!v.is_boolean()) fail_type(v, p, at);
  return v.get<bool>();
}

int64_t read_integer(const json& v, const ParamInfo& p, const At& at) {
  if (!v.is_number()) fail_type(v, p, at);
  // 8.0 is an integer written as a float (1e3 parses as one too); 8.5 is not.
  if (v.is_number_float()) {
    const double x = v.get<double>();
    if (!std::isfinite(x) || x != std::floor(x)) fail_type(v, p, at);
  }
  const double x = checked_number(v, p, at);  // ranges of integer keys lie well within int64
  return static_cast<int64_t>(x);
}

double read_real(const json& v, const ParamInfo& p, const At& at) { return checked_number(v, p, at); }

std::string read_string(const json& v, const ParamInfo& p, const At& at) {
  if (p.kind == Kind::Path && v.is_null()) return "";
  if (!v.is_string()) fail_type(v, p, at);
  std::string s = v.get<std::string>();
  if (p.kind != Kind::Path) return s;
  if (s.empty()) {
    if (p.c.required) at.fail_value(v, "is empty; a path is required");
    return s;
  }
  const std::filesystem::path fp(s);
  if (fp.is_absolute() || at.ctx->folder.empty()) return s;  // absolute paths are left as written
  return (std::filesystem::path(at.ctx->folder) / fp).lexically_normal().string();
}

std::size_t read_enum(const json& v, const ParamInfo& p, const At& at) {
  if (!v.is_string()) fail_type(v, p, at);
  const std::string s = v.get<std::string>();
  for (std::size_t i = 0; i < p.choices.size(); ++i)
    if (p.choices[i] == s) return i;
  std::string best;
  std::size_t best_d = kFar;
  for (const std::string& c : p.choices) {
    const std::size_t d = closeness(s, c);
    if (d < best_d) best_d = d, best = c;
  }
  at.fail_value(v, "is not allowed; allowed: " + quoted_list(p.choices) +
                       (best.empty() ? "" : "; did you mean \"" + best + "\"?"));
}

Vec3 read_vec3(const json& v, const ParamInfo& p, const At& at) {
  if (!v.is_array() || v.size() != 3) fail_type(v, p, at);
  for (const json& x : v)
    if (!x.is_number()) fail_type(v, p, at);
  Vec3 out;
  for (std::size_t i = 0; i < 3; ++i) out[static_cast<int>(i)] = checked_number(v[i], p, at.item(i));
  return out;
}

CubeVoxels read_cube_voxels(const json& v, const ParamInfo& p, const At& at) {
  if (!v.is_array()) return CubeVoxels(static_cast<int>(read_integer(v, p, at)));   // the range keeps it an int
  if (v.size() != 3) fail_type(v, p, at);
  for (const json& x : v)
    if (!x.is_number()) fail_type(v, p, at);
  const ParamInfo element = element_info(p, Kind::Int);
  CubeVoxels out;
  for (std::size_t i = 0; i < 3; ++i) out[static_cast<int>(i)] = static_cast<int>(read_integer(v[i], element, at.item(i)));
  return out;
}

void check_array(const json& v, const ParamInfo& p, const At& at) {
  if (!v.is_array()) fail_type(v, p, at);
  if (v.size() < p.c.min_items || v.size() > p.c.max_items)
    at.fail_value(v, "has " + std::to_string(v.size()) + " items; allowed: " + p.allowed_text());
}

std::vector<int> read_id_list(const json& v, const ParamInfo& p, const At& at) {
  check_array(v, p, at);
  std::vector<int> out;
  std::set<int> seen;
  const ParamInfo element = element_info(p, Kind::Int);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const int id = static_cast<int>(read_integer(v[i], element, at.item(i)));
    if (!seen.insert(id).second) at.item(i).fail_value(v[i], "is listed twice in " + at.path);
    out.push_back(id);
  }
  return out;
}

std::vector<double> read_real_list(const json& v, const ParamInfo& p, const At& at) {
  check_array(v, p, at);
  std::vector<double> out;
  const ParamInfo element = element_info(p, Kind::Real);
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(read_real(v[i], element, at.item(i)));
  return out;
}

// ---- keys --------------------------------------------------------------------------------------

void fail_unknown_key(const TableDoc& table, const std::string& key, const At& at) {
  // A typo of a key of this object first; else the same key (or a near one) in another section,
  // which is where a misplaced key belongs ("pressure_mmhg" at the top level → load.pressure_mmhg).
  std::string best;
  std::size_t best_d = kFar;
  for (std::size_t i = 0; i < table.size(); ++i) {
    const std::size_t d = closeness(key, table.info(i).key);
    if (d < best_d) best_d = d, best = at.child(table.info(i).key).path;
  }
  if (best.empty() && at.ctx->root) {
    std::vector<std::pair<std::string, std::string>> all;
    collect_keys(*at.ctx->root, "", all);
    for (const auto& [name, full] : all) {
      const std::size_t d = closeness(key, name);
      if (d < best_d) best_d = d, best = full;
    }
  }
  std::string hint;
  if (!best.empty()) {
    hint = "; did you mean " + best + "?";
  } else {
    for (std::size_t i = 0; i < table.size(); ++i) hint += (i ? ", " : "") + table.info(i).key;
    hint = "; known keys " + (at.path.empty() ? std::string("at the top level") : "in " + at.path) + ": " + hint;
  }
  at.child(key).fail("is an unknown key" + hint);
}

void fail_missing(const ParamInfo& p, const At& at) {
  at.fail("is missing; it is required (" + p.expected_text() + ")");
}

}  // namespace pneumo::scene_detail

namespace pneumo {

std::string nearest_known_name(const std::string& typed, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_d = scene_detail::kFar;
  for (const std::string& k : known) {
    const std::size_t d = scene_detail::closeness(typed, k);
    if (d < best_d) best_d = d, best = k;
  }
  return best;
}

}  // namespace pneumo
