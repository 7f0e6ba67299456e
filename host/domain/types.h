#pragma once
// The domain's named values: roles, models, methods, lenses, presets, and how scene files spell
// them. The bottom layer every stage shares (roles, mesh, solve, warp, render), so that none of
// them depends on the scene (scene.h composes the stages' settings into a scene file's sections).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace pneumo {

// ---- named values ------------------------------------------------------------------------------

/// What a voxel is in the simulation (§2).
enum class Role : uint8_t { Other = 0, Wall = 1, Viscera = 2, Fixed = 3 };
enum class RoleSource : uint8_t { Labels, Auto };
enum class MeshModel : uint8_t { WallViscera, Wall };
/// Where the CT's grid cuts the body cranially or caudally (mesh.h: MeshOptions::cut_faces).
enum class CutFaces : uint8_t { Slide, Free };
enum class SpringModel : uint8_t { Nonlinear, Linear };
/// The material model on the tetrahedra: the springs of §4–5 or finite elements (solve/fem_element.h).
enum class MaterialModel : uint8_t { Msd, FemCorotational, FemNeoHookean };
enum class RampShape : uint8_t { Smooth, Linear };
enum class SolverMethod : uint8_t { Static, Explicit, Newmark, Kitasaka2004, Newton, ImplicitEuler };
enum class OnInverted : uint8_t { Continue, Stop };
/// The solvers that take any force field (solve/force_field.h), which the finite elements and contact
/// need; the explicit, Newmark and 2004 schemes rely on the springs' own stable step, dampers and
/// stiffness sums.
inline bool solves_force_fields(SolverMethod m) {
  return m == SolverMethod::Static || m == SolverMethod::Newton || m == SolverMethod::ImplicitEuler;
}
enum class Lens : uint8_t { Pinhole, Fisheye };
enum class RenderPreset : uint8_t { Laparoscopic, CtSoftTissue, CtMuscle, CtAaa, CtAir, Skin, Custom };
/// Speed against accuracy (scene_presets.h): what `pneumo bench` measured each to buy.
enum class ScenePreset : uint8_t { None, Preview, Balanced, Accurate };
/// The grid of the deformed CT and labels: the working grid (the CT with the roles' padding, which
/// holds the mesh and so the risen dome) or the input CT's own.
enum class OutputGrid : uint8_t { Working, Input };

/// How each enum's values are written in scene files, indexed by the value: the one place these
/// names are spelled (the parser, the reference and enum_name() all read them from here).
template <class E> struct EnumNames;
template <> struct EnumNames<Role> {
  static constexpr std::array<const char*, 4> names{"other", "wall", "viscera", "fixed"};
};
template <> struct EnumNames<RoleSource> {
  static constexpr std::array<const char*, 2> names{"labels", "auto"};
};
template <> struct EnumNames<MeshModel> {
  static constexpr std::array<const char*, 2> names{"wall_viscera", "wall"};
};
template <> struct EnumNames<CutFaces> {
  static constexpr std::array<const char*, 2> names{"slide", "free"};
};
template <> struct EnumNames<SpringModel> {
  static constexpr std::array<const char*, 2> names{"nonlinear", "linear"};
};
template <> struct EnumNames<MaterialModel> {
  static constexpr std::array<const char*, 3> names{"msd", "fem-corotational", "fem-neohookean"};
};
template <> struct EnumNames<RampShape> {
  static constexpr std::array<const char*, 2> names{"smooth", "linear"};
};
template <> struct EnumNames<SolverMethod> {
  static constexpr std::array<const char*, 6> names{"static", "explicit", "newmark", "kitasaka2004", "newton",
                                                      "implicit-euler"};
};
template <> struct EnumNames<OnInverted> {
  static constexpr std::array<const char*, 2> names{"continue", "stop"};
};
template <> struct EnumNames<Lens> {
  static constexpr std::array<const char*, 2> names{"pinhole", "fisheye"};
};
template <> struct EnumNames<RenderPreset> {
  static constexpr std::array<const char*, 7> names{"laparoscopic", "ct-soft-tissue", "ct-muscle",
                                                    "ct-aaa", "ct-air", "skin", "custom"};
};

template <> struct EnumNames<OutputGrid> {
  static constexpr std::array<const char*, 2> names{"working", "input"};
};
template <> struct EnumNames<ScenePreset> {
  static constexpr std::array<const char*, 4> names{"none", "preview", "balanced", "accurate"};
};

/// The scene-file name of an enum value ("kitasaka2004", "ct-muscle", ...).
template <class E> const char* enum_name(E e) {
  return EnumNames<E>::names[static_cast<std::size_t>(e)];
}
inline const char* role_name(Role r) { return enum_name(r); }

/// The enum value a scene file's name spells, or nothing when it spells none.
template <class E> std::optional<E> enum_from_name(std::string_view name) {
  for (std::size_t i = 0; i < EnumNames<E>::names.size(); ++i)
    if (name == EnumNames<E>::names[i]) return static_cast<E>(i);
  return std::nullopt;
}

}  // namespace pneumo
