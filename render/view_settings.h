#pragma once
// What the renderer is asked to draw (method.md §8): optics, cameras, ports on the skin, camera
// paths and the look of the volume; the scene's "render" section. Positions are world RAS+ mm.
#include <optional>
#include <string>
#include <vector>

#include "core/geometry.h"
#include "domain/types.h"

namespace pneumo {

/// Optics shared by cameras, ports and paths (§8).
struct Optics {
  Vec3 up = Vec3(0.0, 0.0, 1.0);  // superior (RAS+ world)
  double fov_deg = 70.0;
  Lens lens = Lens::Pinhole;
  double oblique_deg = 0.0;
  double roll_deg = 0.0;
  double near_mm = 1.0;
};

struct Camera {
  std::string name;
  Vec3 position_mm = Vec3::Zero();
  Vec3 look_at_mm = Vec3::Zero();
  Optics optics;
};

/// A trocar port on the skin, carried through the deformation, aimed at a point or an organ.
struct Port {
  std::string name;
  Vec3 skin_point_mm = Vec3::Zero();
  std::optional<Vec3> target_mm;   // exactly one of target_mm, target_label
  std::optional<int> target_label;
  double insertion_mm = 40.0;      // tip beyond the skin point, along the port axis
  Optics optics;
};

struct Keyframe {
  Vec3 position_mm = Vec3::Zero();
  Vec3 look_at_mm = Vec3::Zero();
};

struct CameraPath {
  std::string name;
  int frames = 60;
  std::vector<Keyframe> keyframes;  // at least 2
  Optics optics;
};

/// The width of the Gaussian the views' copy of the CT is prefiltered with, in mm, at least a voxel
/// on each axis (render_volume.h view_smoothing_sigma_voxels says why).
inline constexpr double kDefaultSmoothingMm = 1.5;

/// How the views are rendered and from where: the scene's "render" section.
struct ViewSettings {
  int width = 640, height = 480;
  RenderPreset preset = RenderPreset::Laparoscopic;
  double step_fraction = 0.5;     // §8: step ≤ half the smallest spacing
  bool jitter = false;            // off: images are reproducible
  bool show_labels = true;
  double label_opacity = 0.5;
  double light_falloff_mm = 100.0;  // d0 of the headlight's 1/(1+(d/d0)²) (§8)
  double smoothing_mm = kDefaultSmoothingMm;   // σ of the views' prefilter, ≥ 1 voxel (render_volume.h)
  double vignetting_power = 0.0;   // laparoscope views × cosⁿ of the field angle (render_settings.h step 6)
  int antialias_samples = 1;       // passes averaged per view (render_settings.h step 7)
  // Phong coefficients; VTK's defaults for volumes lit by a headlight (ambient low: the scope's
  // own light is the only light in the abdomen).
  double ambient = 0.15, diffuse = 0.85, specular = 0.25, shininess = 12.0;
  // preset "custom": Slicer-style flat lists [HU, α, HU, α, ...] and [HU, r, g, b, ...].
  std::vector<double> custom_opacity, custom_colour;
  bool exterior_views = true;     // the skin from the front and the left, before | after, ports marked
  std::vector<Camera> cameras;
  std::vector<Port> ports;
  std::vector<CameraPath> paths;
  double video_fps = 25.0;        // frame rate of the fly-through and inflation-preview MP4s
};

}  // namespace pneumo
