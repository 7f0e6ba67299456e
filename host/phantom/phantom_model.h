#pragma once
// Internals of the synthetic abdomen (not part of the public API): label ids, nominal HU values with their
// sources, the torso model, and the primitives the anatomy is painted from.
//
// How a phantom is made: the torso model assigns every (x, y) column a zone (air, skin, subcutaneous fat, muscle,
// cavity) once per grid. Then each axial slice is painted independently: the torso's base labels first, then the
// shapes of the anatomy table in priority order, later shapes overriding earlier ones. A shape only paints where
// its zone mask allows (organs only inside the cavity, the table only in the air, ...), and tests its bounding box
// before any per-voxel work. Everything is in millimetres; the grid only decides where the samples fall.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Dense>

namespace pneumo::phantom_detail {

using V2 = Eigen::Vector2d;
using V3 = Eigen::Vector3d;

// ---- label ids: TotalSegmentator v2 "total" (Wasserthal et al., Radiology: AI 2023, class map v2) -----------------
namespace label {
constexpr uint8_t kBackground = 0;
constexpr uint8_t kSpleen = 1, kKidneyRight = 2, kKidneyLeft = 3, kGallbladder = 4, kLiver = 5, kStomach = 6,
                  kPancreas = 7;
constexpr uint8_t kLungLowerLobeLeft = 11, kLungLowerLobeRight = 14;
constexpr uint8_t kSmallBowel = 18, kDuodenum = 19, kColon = 20;
constexpr uint8_t kSacrum = 25;
constexpr uint8_t kVertebraL5 = 27, kVertebraL4 = 28, kVertebraL3 = 29, kVertebraL2 = 30, kVertebraL1 = 31,
                  kVertebraT12 = 32, kVertebraT11 = 33, kVertebraT10 = 34, kVertebraT9 = 35, kVertebraT8 = 36,
                  kVertebraT7 = 37;
constexpr uint8_t kHeart = 51, kAorta = 52, kInferiorVenaCava = 63, kPortalVein = 64;
constexpr uint8_t kIliacArteryLeft = 65, kIliacArteryRight = 66, kIliacVeinLeft = 67, kIliacVeinRight = 68;
constexpr uint8_t kHipLeft = 77, kHipRight = 78, kSpinalCord = 79;
constexpr uint8_t kGluteusMediusLeft = 82, kGluteusMediusRight = 83;
constexpr uint8_t kAutochthonLeft = 86, kAutochthonRight = 87, kIliopsoasLeft = 88, kIliopsoasRight = 89;
constexpr uint8_t kRibLeft1 = 92, kRibRight1 = 104;   // rib_left_n = 91 + n, rib_right_n = 103 + n
constexpr uint8_t kSternum = 116, kCostalCartilages = 117;
// Structures TotalSegmentator's "total" task lacks: ids from 200 up.
constexpr uint8_t kSkin = 200, kSubcutaneousFat = 201, kAbdominalWallMuscle = 202, kIntraperitonealFat = 203,
                  kCtTable = 204, kCtTablePad = 205, kIntervertebralDisc = 206, kDiaphragm = 207;
constexpr uint8_t rib_left(int n) { return static_cast<uint8_t>(91 + n); }
constexpr uint8_t rib_right(int n) { return static_cast<uint8_t>(103 + n); }
}  // namespace label

// ---- nominal HU (non-contrast CT, 120 kVp); the label table repeats each with its source ------------------------
namespace hu {
constexpr float kAir = -1000;          // definition of the Hounsfield scale
constexpr float kGas = -1000;          // bowel gas is air-like
constexpr float kLung = -850;          // aerated lung at inspiration: −900…−800
constexpr float kFat = -100;           // adipose tissue −120…−80
constexpr float kMesentericFat = -95;  // mesenteric fat with its fine vessels, slightly above pure fat
constexpr float kSkin = 40;
constexpr float kMuscle = 50;          // skeletal muscle 40…60
constexpr float kLiver = 60;           // normal unenhanced liver 55…65
constexpr float kSpleen = 48;          // ≈ 8–10 HU below the liver
constexpr float kKidney = 32;          // renal parenchyma 30…35
constexpr float kPancreas = 42;        // 40…50
constexpr float kBlood = 40;           // unenhanced blood 35…45 (haematocrit-dependent)
constexpr float kBowelWall = 40;
constexpr float kBowelFluid = 15;      // enteric fluid without oral contrast 0…20
constexpr float kGastricFluid = 18;
constexpr float kStool = 30;           // faeces without gas: 0…60, mottled with gas bubbles
constexpr float kBile = 10;            // gallbladder bile 0…20
constexpr float kCsf = 20;             // CSF 0…15 with the cord (≈ 35) partial-volumed
constexpr float kCorticalBone = 1000;  // compact bone 700…1900 at CT resolution
constexpr float kCancellousBone = 200; // adult lumbar trabecular bone 150…250 (L1: Pickhardt 2013)
constexpr float kDisc = 80;            // intervertebral disc 70…100
constexpr float kCartilage = 120;      // non-calcified costal cartilage 100…150
constexpr float kSternum = 300;        // sternum/xiphoid: thin cortex around cancellous bone
constexpr float kTableShell = 200;     // carbon-fibre composite skin of the table top
constexpr float kTableFoam = -950;     // rigid foam core (≈ 50 kg/m³)
constexpr float kPadFoam = -900;       // mattress foam (≈ 100 kg/m³)
}  // namespace hu

// ---- the sampled plane of one axial slice -------------------------------------------------------------------------
struct PlaneGrid {
  int nx = 0, ny = 0;
  double x0_mm = 0, y0_mm = 0, dx_mm = 1, dy_mm = 1;   // centre of pixel (0,0) and spacing
  double min_spacing_mm = 1;                            // smallest of the 3-D spacings (thin layers)
  double x(int i) const { return x0_mm + i * dx_mm; }
  double y(int j) const { return y0_mm + j * dy_mm; }
  // First/last pixel whose centre lies in [lo, hi]; empty when lo > hi.
  int i_first(double lo_mm) const;
  int i_last(double hi_mm) const;
  int j_first(double lo_mm) const;
  int j_last(double hi_mm) const;
  int64_t size() const { return int64_t(nx) * ny; }
};

// ---- zones of the torso -----------------------------------------------------------------------------------------
enum Zone : uint8_t { kZoneOut = 0, kZoneSkin = 1, kZoneSubcut = 2, kZoneMuscle = 3, kZoneCavity = 4 };
using ZoneMask = uint8_t;
constexpr ZoneMask zone_bit(Zone z) { return static_cast<ZoneMask>(1u << z); }
constexpr ZoneMask kInCavity = zone_bit(kZoneCavity);
constexpr ZoneMask kInMuscleOrCavity = zone_bit(kZoneMuscle) | zone_bit(kZoneCavity);
constexpr ZoneMask kUnderSkin = zone_bit(kZoneSubcut) | zone_bit(kZoneMuscle) | zone_bit(kZoneCavity);
constexpr ZoneMask kOutside = zone_bit(kZoneOut);

/// The torso: a supine cross-section, the same at every z (the abdomen is close to a prism between the lower ribs
/// and the iliac crests). Outline: |x/a|^n + |y/b|^n = 1 with n = 2 anteriorly (an ellipse) and n = 3 posteriorly
/// (the back is flattened on the table). Layers inward from the skin, thicknesses depending on the angle
/// θ (0 = patient right, 90° = anterior): skin, subcutaneous fat, muscle (rectus, obliques, posterior muscles).
struct TorsoModel {
  // Adult abdomen ≈ 320 mm lateral × 220 mm AP (AAPM Report 204, 2011: lateral 30–35 cm, AP 20–25 cm for average
  // adults; effective diameter ≈ 26.5 cm).
  double semi_lateral_mm = 160, semi_ap_mm = 110;
  double n_anterior = 2, n_posterior = 3;
  double skin_nominal_mm = 2;   // epidermis + dermis of the abdomen ≈ 1.5–2.5 mm (high-frequency ultrasound)

  /// Point of the skin outline in direction θ (radians) from the body centre (0, 0).
  V2 outline(double theta) const;
  /// Skin thickness actually drawn: nominal, but never thinner than one voxel so that the skin label is continuous
  /// (its HU is blended with fat to keep the nominal contrast; a partial-volume approximation).
  double skin_mm(double min_spacing_mm) const;
  /// Subcutaneous fat: ≈ 18 mm anteriorly (mid-abdomen, normal BMI), 10 mm laterally, 14 mm posteriorly.
  double subcut_fat_mm(double theta) const;
  /// Muscle layer at the skin point with lateral coordinate x_b: linea alba 3 mm (|x_b| < 6 mm), rectus abdominis
  /// ≈ 10 mm, the three lateral flat muscles together ≈ 13 mm, posterior (latissimus, quadratus lumborum) 16 mm.
  double muscle_mm(double theta, double x_b_mm) const;
};

/// Per (x, y) column of the grid: zone, base label and base HU (skin/fat/muscle/cavity fat), depth below the skin.
struct TorsoMaps {
  std::vector<uint8_t> zone, base_label;
  std::vector<float> base_hu, depth_mm;
  void build(const TorsoModel& torso, const PlaneGrid& g);
};

// ---- how a shape fills the voxels it covers ---------------------------------------------------------------------
enum class Content : uint8_t {
  Fluid,          // hollow organ holding fluid (hu_inner)
  GasCap,         // fluid with gas above a level relative to the tube axis: y − y_axis > gas_level · radius
  GasAbovePlane,  // fluid with gas above an absolute plane y > gas_level (mm): a supine air-fluid level
  Stool,          // mottled faeces with small gas bubbles (hash texture in mm, grid-independent)
};

struct Fill {
  enum class Kind : uint8_t { Solid, Bone, Hollow } kind = Kind::Solid;
  float hu = 0;         // Solid: value; Bone: cortex; Hollow: wall
  float hu_inner = 0;   // Bone: cancellous; Hollow: contents
  float rim_mm = 0;     // Bone: cortical thickness; Hollow: wall thickness
  Content content = Content::Fluid;
  float gas_level = 0;  // see Content

  static Fill solid(float v) { Fill f; f.hu = v; return f; }
  static Fill bone(float cortical, float cancellous, float cortex_mm) {
    Fill f; f.kind = Kind::Bone; f.hu = cortical; f.hu_inner = cancellous; f.rim_mm = cortex_mm; return f;
  }
  static Fill hollow(float wall, float contents, float wall_mm, Content c = Content::Fluid, float gas_level = 0) {
    Fill f; f.kind = Kind::Hollow; f.hu = wall; f.hu_inner = contents; f.rim_mm = wall_mm; f.content = c;
    f.gas_level = gas_level; return f;
  }
};

/// Where a voxel lies inside the shape that fills it: its depth below the shape's surface (mm), its position, and
/// for tubes the height above the local axis and the local radius (for air-fluid levels).
struct FillSample {
  double depth_mm;
  double x_mm, y_mm, z_mm;
  double y_above_axis_mm = 0, radius_mm = 1;
};

/// The HU of a voxel filled by `f`. A rim thinner than a voxel is widened to one voxel and its HU blended towards
/// the interior so that rim × contrast is preserved (partial volume).
float fill_hu(const Fill& f, const FillSample& s, double min_spacing_mm);

/// Smooth value noise in [0, 1) on a lattice of `cell_mm` (trilinear between hashed lattice values), in world mm
/// so that every grid samples the same texture.
float value_noise(double x_mm, double y_mm, double z_mm, double cell_mm, uint64_t seed);

/// Gaussian-like noise (σ = 1) from a counter-based hash of the voxel index: the same at any thread count.
float voxel_noise(int64_t i, int64_t j, int64_t k);

// ---- painting -----------------------------------------------------------------------------------------------------
/// One axial slice being painted: labels and HU per pixel, plus per-thread scratch for tubes.
struct Slice {
  double z_mm = 0;
  std::vector<uint8_t> label;
  std::vector<float> hu;
  std::vector<float> scratch_depth;    // tubes: best depth so far
  std::vector<int32_t> scratch_seg;    // tubes: segment of the best depth
  void resize(int64_t n);
};

struct PaintContext {
  const PlaneGrid& grid;
  const TorsoMaps& torso;
};

class Shape {
 public:
  virtual ~Shape() = default;
  /// Paints the shape's voxels of slice s (z = s.z_mm). Must depend on nothing but the slice and the context.
  virtual void paint(const PaintContext& ctx, Slice& s) const = 0;
  /// Called once per grid before painting (2-D caches).
  virtual void prepare(const PlaneGrid&, const TorsoModel&) {}
};

/// Common settings of a painted shape.
struct Paint {
  uint8_t label = 0;
  Fill fill;
  ZoneMask zones = kInCavity;
  int only_over = -1;   // ≥ 0: paint only over voxels already holding this label (vessels inside an organ)
};

/// An ellipsoid with semi-axes along the columns of `axes` (orthonormal): long, middle, short.
struct EllipsoidSpec {
  const char* what;
  V3 centre_mm;
  V3 semi_mm;
  V3 axis1 = V3::UnitX();   // direction of semi_mm[0]
  V3 axis2_hint = V3::UnitY();  // direction of semi_mm[1] after Gram–Schmidt against axis1
  Paint paint;
};
std::unique_ptr<Shape> make_ellipsoid(const EllipsoidSpec& spec);

/// A tube swept along a polyline: capsules with linearly varying radius, unioned (a voxel takes the segment it is
/// deepest in). Per node: position and radius; per segment (node n → n+1): whether it holds a gas cap.
struct TubeNode {
  V3 p_mm;
  double r_mm;
  bool gas = false;   // segment from this node to the next holds gas (Fill content switched to GasCap)
};
struct TubeSpec {
  const char* what;
  std::vector<TubeNode> nodes;
  Paint paint;
  float gas_cap_level = 0.3f;   // GasCap level for segments marked gas
};
std::unique_ptr<Shape> make_tube(TubeSpec spec);

/// A vertical prism whose cross-section, a superellipse |dx/ax|^n + |dy/ay|^n ≤ 1 (n = 2 or 4), is given per slice
/// by a function of z (centre and semi-axes follow the spine, for example). Depth for Bone fills is measured to the
/// side and to the end caps z_lo/z_hi.
struct PrismSection {
  V2 centre_mm;
  V2 semi_mm;
  bool valid = true;
};
struct PrismSpec {
  const char* what;
  double z_lo_mm, z_hi_mm;
  int exponent = 2;   // 2 or 4
  std::function<PrismSection(double z_mm)> section;
  Paint paint;
};
std::unique_ptr<Shape> make_prism(PrismSpec spec);

/// A custom shape defined by a per-slice painting function (spine, thorax, table, iliac wings).
std::unique_ptr<Shape> make_custom(std::function<void(const PaintContext&, Slice&)> paint,
                                   std::function<void(const PlaneGrid&, const TorsoModel&)> prepare = {});

/// Paints one voxel if the zone and only_over rules allow it.
inline bool paint_allowed(const Paint& p, const PaintContext& ctx, const Slice& s, int64_t n) {
  if (!(p.zones & zone_bit(static_cast<Zone>(ctx.torso.zone[n])))) return false;
  return p.only_over < 0 || s.label[n] == p.only_over;
}

// ---- the anatomy ----------------------------------------------------------------------------------------------------
struct Anatomy {
  TorsoModel torso;
  std::vector<std::unique_ptr<Shape>> shapes;   // in painting (priority) order
};
/// The shape table: builds the body in mm (independent of the grid).
Anatomy build_anatomy();

/// Spine centre (centre of the vertebral bodies) in y, mm, as a function of z: lumbar lordosis, thoracic kyphosis,
/// sacral tilt.
double spine_y_mm(double z_mm);

}  // namespace pneumo::phantom_detail
