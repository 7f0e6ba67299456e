#pragma once
// The mechanism behind the scene's parameter table (internal to host/scene and its tests).
//
// A Table<O> lists the keys of one JSON object and binds each to a field of the C++ struct O.
// One Param describes one key: its name, unit, constraints and meaning (ParamInfo, plain data that
// messages and the reference read), plus two closures made from a member pointer, read and write.
// The field's C++ type picks how its JSON is read (Value<T> below): bool, integers, double,
// strings and paths, enums, 3-vectors, id and number lists, std::optional of any of these; a
// nested struct with its own table is a section, a std::vector of one an array of objects. So
// scalars, enums, vectors, id lists and object arrays all go through the same few functions, and
// an error anywhere names the file, the key's full path ("render.cameras[1].fov_deg"), the value
// and what is allowed.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/cube_voxels.h"
#include "core/geometry.h"
#include "scene/scene.h"

namespace pneumo::scene_detail {

using json = nlohmann::json;

enum class Kind { Bool, Int, Real, String, Path, Enum, Vec3, IdList, RealList, Section, ObjectArray, CubeVoxels };

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr std::size_t kNoLimit = std::numeric_limits<std::size_t>::max();

/// An interval of numbers; each end closed or open, possibly infinite.
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;
  bool contains(double x) const;
  std::string text() const;  // "0 to 100", "> 0 and <= 1", ">= 0", "any"
};

/// What a key allows beyond its type. Made with the helpers below and refined by chaining:
///   in(0, 100)   above(0, 1)   at_least(0).rule("non-decreasing", fn)   required()   file_path()
struct Constraint {
  Range range;  // numbers; each element of lists and 3-vectors
  std::size_t min_items = 0, max_items = kNoLimit;  // lists and arrays of objects
  bool required = false;
  bool is_path = false;  // a file path: relative ones resolve against the scene's folder
  const char* rule_text = nullptr;               // a further condition, in words
  bool (*rule_ok)(const json& value) = nullptr;  // ... and its test on the (type-checked) value

  Constraint items(std::size_t lo, std::size_t hi = kNoLimit) const;
  Constraint rule(const char* text, bool (*ok)(const json&)) const;
  Constraint req() const;
};
Constraint any();
Constraint in(double lo, double hi);              // [lo, hi]
Constraint above(double lo, double hi = kInf);    // (lo, hi]
Constraint at_least(double lo);                   // [lo, ∞)
Constraint required();
Constraint file_path();

struct TableDoc;

/// One key, as messages and the reference see it.
struct ParamInfo {
  std::string key;    // its name in its object
  Kind kind = Kind::Real;
  std::string unit;   // "mm", "mmHg", ...; "" when it has none
  std::string meaning;
  Constraint c;
  bool optional = false;             // may be null (or absent) meaning "not set"
  std::vector<std::string> choices;  // enums
  const TableDoc* sub = nullptr;     // sections and arrays of objects: the table of their keys

  std::string type_text() const;      // for the reference: "number", "[x, y, z]", ...
  std::string expected_text() const;  // for messages: "a number", "an array of 3 numbers", ...
  std::string allowed_text() const;   // for both: "0 to 100", "\"static\", \"explicit\"", ...
};

/// What is being read: the file for messages, the folder for relative paths, and the root table
/// so that a misplaced key can be pointed to where it belongs.
struct ReadContext {
  std::string file;
  std::string folder;
  const TableDoc* root = nullptr;
};

/// Where a value sits: its key's full path. Every error goes through fail()/fail_value(), so all
/// messages have one shape: "<file>: <path> = <value> <problem>".
struct At {
  const ReadContext* ctx = nullptr;
  std::string path;
  At child(const std::string& key) const;
  At item(std::size_t i) const;
  [[noreturn]] void fail(const std::string& problem) const;
  [[noreturn]] void fail_value(const json& value, const std::string& problem) const;
};

/// A value in a message: compact JSON, cut short when long.
std::string show(const json& value);

/// The table of the keys of one kind of object, without the C++ type behind it (for the
/// reference, the suggestions and the defaults).
struct TableDoc {
  virtual ~TableDoc() = default;
  virtual std::size_t size() const = 0;
  virtual const ParamInfo& info(std::size_t i) const = 0;
  virtual json defaults() const = 0;  // a default-constructed object, written out
  const ParamInfo* find(const std::string& key) const;
};

// ---- reading and writing one value (param_codec.cpp) --------------------------------------------
bool read_bool(const json& v, const ParamInfo& p, const At& at);
int64_t read_integer(const json& v, const ParamInfo& p, const At& at);
double read_real(const json& v, const ParamInfo& p, const At& at);
std::string read_string(const json& v, const ParamInfo& p, const At& at);  // resolves paths
std::size_t read_enum(const json& v, const ParamInfo& p, const At& at);
Vec3 read_vec3(const json& v, const ParamInfo& p, const At& at);
std::vector<int> read_id_list(const json& v, const ParamInfo& p, const At& at);
std::vector<double> read_real_list(const json& v, const ParamInfo& p, const At& at);
/// One integer for all three axes or [i, j, k], each within the key's range.
CubeVoxels read_cube_voxels(const json& v, const ParamInfo& p, const At& at);
/// The array check shared by lists and arrays of objects: type and item count.
void check_array(const json& v, const ParamInfo& p, const At& at);
[[noreturn]] void fail_unknown_key(const TableDoc& table, const std::string& key, const At& at);
[[noreturn]] void fail_missing(const ParamInfo& p, const At& at);

/// How a field's C++ type is read and written.
template <class T, class = void> struct Value;

template <> struct Value<bool> {
  static constexpr Kind kind = Kind::Bool;
  static bool read(const json& v, const ParamInfo& p, const At& at) { return read_bool(v, p, at); }
  static json write(bool b, const ParamInfo&) { return b; }
};
template <class T>
struct Value<T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>>> {
  static constexpr Kind kind = Kind::Int;
  static T read(const json& v, const ParamInfo& p, const At& at) {
    return static_cast<T>(read_integer(v, p, at));  // the range keeps it within T
  }
  static json write(T x, const ParamInfo&) { return static_cast<int64_t>(x); }
};
template <> struct Value<double> {
  static constexpr Kind kind = Kind::Real;
  static double read(const json& v, const ParamInfo& p, const At& at) { return read_real(v, p, at); }
  static json write(double x, const ParamInfo&) { return x; }
};
template <> struct Value<std::string> {
  static constexpr Kind kind = Kind::String;  // Kind::Path with file_path()
  static std::string read(const json& v, const ParamInfo& p, const At& at) { return read_string(v, p, at); }
  static json write(const std::string& s, const ParamInfo& p) {
    return (p.kind == Kind::Path && s.empty()) ? json(nullptr) : json(s);
  }
};
template <> struct Value<Vec3> {
  static constexpr Kind kind = Kind::Vec3;
  static Vec3 read(const json& v, const ParamInfo& p, const At& at) { return read_vec3(v, p, at); }
  static json write(const Vec3& x, const ParamInfo&) { return json::array({x[0], x[1], x[2]}); }
};
template <> struct Value<CubeVoxels> {
  static constexpr Kind kind = Kind::CubeVoxels;
  static CubeVoxels read(const json& v, const ParamInfo& p, const At& at) { return read_cube_voxels(v, p, at); }
  static json write(const CubeVoxels& x, const ParamInfo&) {   // as written: one integer when all axes agree
    return x.uniform() ? json(x[0]) : json::array({x[0], x[1], x[2]});
  }
};
template <> struct Value<std::vector<int>> {
  static constexpr Kind kind = Kind::IdList;
  static std::vector<int> read(const json& v, const ParamInfo& p, const At& at) { return read_id_list(v, p, at); }
  static json write(const std::vector<int>& x, const ParamInfo&) { return x; }
};
template <> struct Value<std::vector<double>> {
  static constexpr Kind kind = Kind::RealList;
  static std::vector<double> read(const json& v, const ParamInfo& p, const At& at) { return read_real_list(v, p, at); }
  static json write(const std::vector<double>& x, const ParamInfo&) { return x; }
};
template <class E> struct Value<E, std::enable_if_t<std::is_enum_v<E>>> {
  static constexpr Kind kind = Kind::Enum;
  static std::vector<std::string> choices() {
    return {std::begin(EnumNames<E>::names), std::end(EnumNames<E>::names)};
  }
  static E read(const json& v, const ParamInfo& p, const At& at) { return static_cast<E>(read_enum(v, p, at)); }
  static json write(E e, const ParamInfo&) { return EnumNames<E>::names[static_cast<std::size_t>(e)]; }
};
template <class T> struct Value<std::optional<T>> {
  static constexpr Kind kind = Value<T>::kind;
  static std::optional<T> read(const json& v, const ParamInfo& p, const At& at) {
    if (v.is_null()) return std::nullopt;
    return Value<T>::read(v, p, at);
  }
  static json write(const std::optional<T>& x, const ParamInfo& p) {
    return x ? Value<T>::write(*x, p) : json(nullptr);
  }
};

template <class T> struct IsOptional : std::false_type {};
template <class T> struct IsOptional<std::optional<T>> : std::true_type {};
template <class T, class = void> struct HasChoices : std::false_type {};
template <class T> struct HasChoices<T, std::void_t<decltype(Value<T>::choices())>> : std::true_type {};
template <class T> struct HasChoices<std::optional<T>> : HasChoices<T> {};

template <class T> std::vector<std::string> choices_of() {
  if constexpr (IsOptional<T>::value) return choices_of<typename T::value_type>();
  else if constexpr (HasChoices<T>::value) return Value<T>::choices();
  else return {};
}

template <class O> class Table;

/// One key of the object O.
template <class O> struct Param {
  ParamInfo info;
  std::function<void(O&, const json&, const ParamInfo&, const At&)> read;
  std::function<json(const O&, const ParamInfo&)> write;

  Param() = default;

  /// A value: the field's type decides how it is read.
  template <class T>
  Param(const char* key, T O::*field, const char* unit, Constraint c, const char* meaning) {
    info = make_info(key, Value<T>::kind, unit, c, meaning);
    if (c.is_path) info.kind = Kind::Path;
    // A path may always be left out ("" = not given); other keys only when their type says so.
    info.optional = IsOptional<T>::value || (c.is_path && !c.required);
    info.choices = choices_of<T>();
    read = [field](O& o, const json& v, const ParamInfo& p, const At& at) {
      if (v.is_null() && !p.optional)
        at.fail_value(v, "has the wrong type; expected " + p.expected_text());
      o.*field = Value<T>::read(v, p, at);
      if (p.c.rule_ok && !v.is_null() && !p.c.rule_ok(v))
        at.fail_value(v, std::string("is not allowed; ") + p.c.rule_text);
    };
    write = [field](const O& o, const ParamInfo& p) { return Value<T>::write(o.*field, p); };
  }

  /// A section: a nested object read with its own table.
  template <class S>
  Param(const char* key, S O::*field, const Table<S>& table, const char* meaning) {
    info = make_info(key, Kind::Section, "", any(), meaning);
    info.sub = &table;
    read = [field, &table](O& o, const json& v, const ParamInfo&, const At& at) {
      table.read(o.*field, v, at);
    };
    write = [field, &table](const O& o, const ParamInfo&) { return table.write(o.*field); };
  }

  /// An array of objects, each read with the item table (paths "key[i].item_key").
  template <class I>
  Param(const char* key, std::vector<I> O::*field, const Table<I>& table, Constraint c, const char* meaning) {
    info = make_info(key, Kind::ObjectArray, "", c, meaning);
    info.sub = &table;
    read = [field, &table](O& o, const json& v, const ParamInfo& p, const At& at) {
      check_array(v, p, at);
      std::vector<I> items(v.size());
      for (std::size_t i = 0; i < v.size(); ++i) table.read(items[i], v[i], at.item(i));
      o.*field = std::move(items);
    };
    write = [field, &table](const O& o, const ParamInfo&) {
      json a = json::array();
      for (const I& item : o.*field) a.push_back(table.write(item));
      return a;
    };
  }

 private:
  static ParamInfo make_info(const char* key, Kind kind, const char* unit, const Constraint& c, const char* meaning) {
    ParamInfo p;
    p.key = key;
    p.kind = kind;
    p.unit = unit;
    p.meaning = meaning;
    p.c = c;
    return p;
  }
};

/// The keys of one kind of object, in the order the reference lists them.
template <class O> class Table : public TableDoc {
 public:
  /// `inlined`: keys of a member struct written flat into this object (see inline_params).
  Table(std::initializer_list<Param<O>> params, std::vector<Param<O>> inlined = {})
      : params_(params) {
    params_.insert(params_.end(), inlined.begin(), inlined.end());
  }

  std::size_t size() const override { return params_.size(); }
  const ParamInfo& info(std::size_t i) const override { return params_[i].info; }
  json defaults() const override { return write(O{}); }
  const std::vector<Param<O>>& params() const { return params_; }

  /// Fills `o` from the object `j`; keys not in `j` keep the value `o` has (its default).
  void read(O& o, const json& j, const At& at) const {
    if (!j.is_object()) at.fail_value(j, "has the wrong type; expected an object");
    for (auto it = j.begin(); it != j.end(); ++it)
      if (!find(it.key())) fail_unknown_key(*this, it.key(), at);
    for (const Param<O>& p : params_) {
      const At here = at.child(p.info.key);
      const auto it = j.find(p.info.key);
      if (it == j.end()) {
        if (p.info.c.required) fail_missing(p.info, here);
        continue;
      }
      p.read(o, *it, p.info, here);
    }
  }

  json write(const O& o) const {
    json j = json::object();
    for (const Param<O>& p : params_) j[p.info.key] = p.write(o, p.info);
    return j;
  }

 private:
  std::vector<Param<O>> params_;
};

/// The keys of the member struct `O::*field` (e.g. a camera's optics), to be written flat in O's
/// objects: cameras, ports and paths share one optics table this way.
template <class O, class S>
std::vector<Param<O>> inline_params(S O::*field, const Table<S>& table) {
  std::vector<Param<O>> out;
  for (const Param<S>& s : table.params()) {
    Param<O> p;
    p.info = s.info;
    p.read = [field, r = s.read](O& o, const json& v, const ParamInfo& i, const At& at) { r(o.*field, v, i, at); };
    p.write = [field, w = s.write](const O& o, const ParamInfo& i) { return w(o.*field, i); };
    out.push_back(std::move(p));
  }
  return out;
}

/// The table of the whole scene (scene_params.cpp).
const Table<Scene>& scene_table();
/// The table of one item of render.ports (scene_params.cpp): pneumo serve reads and writes ports with it.
const Table<Port>& scene_port_table();
/// A port's cross-key rules (scene_validate.cpp): one target, a lens its field of view allows, a
/// direction from the skin point to a target point.
void check_port(const Port& p, const At& at);
/// Cross-key rules the table cannot express (scene_validate.cpp): a label in two role lists,
/// ROI corners, port targets, unique view names, camera geometry.
void validate_scene(const Scene& s, const ReadContext& ctx);
/// The label map's names into roles.label_names, for messages, whatever the source. Then roles by anatomy
/// (scene_roles_by_name.cpp): with roles.source "auto", roles.by_name and a label map
/// whose ids have names (inputs.label_names, else the map's own NIfTI header), the ids no list of the
/// scene names join the lists their structure's name gives (roles/structure_names.h), and so do
/// roles.auto_prevesical_labels and mesh.attached_labels where `given` (the scene's JSON) lacks them.
void assign_roles_by_name(Scene& s, const nlohmann::json& given);
}  // namespace pneumo::scene_detail
