#include "render/ray_cast_gl.h"

#include <cmath>
#include <limits>
#include <array>
#include <map>
#include <optional>
#include <stdexcept>

#include "core/error.h"
#include "core/log.h"
#include "render/gl_api.h"
#include "render/shader_program.h"

namespace pneumo {
namespace {

GLuint make_texture(GLenum target, GLint filter) {
  const gl::Api& g = gl::api();
  GLuint t = 0;
  g.GenTextures(1, &t);
  g.BindTexture(target, t);
  // Every texture sets its min filter: the default wants mipmaps, and without them it is incomplete.
  g.TexParameteri(target, GL_TEXTURE_MIN_FILTER, filter);
  g.TexParameteri(target, GL_TEXTURE_MAG_FILTER, filter);
  g.TexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  g.TexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (target == GL_TEXTURE_3D) g.TexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  return t;
}

// What the occupancy grid depends on besides the volume, compared exactly (a rounded text key would
// take an opacity of 1e-7 for 0 and keep blocks skipped that must be drawn).
struct OccupancyKey {
  bool hide_exterior_air = false;
  decltype(TransferFunction::opacity) opacity;
  bool operator==(const OccupancyKey& o) const {
    return hide_exterior_air == o.hide_exterior_air && opacity == o.opacity;
  }
};
OccupancyKey occupancy_key(const RenderSettings& s) { return {s.hide_exterior_air, s.tf.opacity}; }

}  // namespace

struct GlRayCaster::Impl {
  GlContext& ctx;
  std::map<std::string, std::unique_ptr<gl::ShaderProgram>> programs;  // by variant (#defines)
  GLuint vao = 0, fbo = 0, colour_tex = 0, depth_tex = 0;
  GLuint hu_tex = 0, grad_tex = 0, label_tex = 0, occ_tex = 0, tf_tex = 0, label_colour_tex = 0;
  // The labels on the views' grid: set_volume's volume's own (it outlives the renders), or, where
  // the views' grid is coarser (view_grid_stride), the copy kept here.
  const std::vector<uint16_t>* labels = nullptr;
  std::vector<uint16_t> resampled_labels;
  std::optional<std::vector<std::array<uint8_t, 4>>> colours_uploaded;   // none: no colour volume yet
  bool packed = false;  // hu_tex holds (HU, gradient); grad_tex unused
  int fb_width = 0, fb_height = 0;
  bool have_volume = false;
  Geometry geometry;
  Mat3 w2i = Mat3::Identity();
  float hu_scale = 1.0f;
  std::string hu_format = "none";
  BlockRanges ranges;
  std::optional<OccupancyKey> occ_key;   // none: no grid built for the current volume

  explicit Impl(GlContext& c) : ctx((c.make_current(), c)) {
    program(true, true, false);  // compile the common variant now: shader errors surface here
    const gl::Api& g = gl::api();
    g.GenVertexArrays(1, &vao);
    g.GenFramebuffers(1, &fbo);
    gl::check_error("GL ray caster setup");
  }

  ~Impl() {
    const gl::Api& g = gl::api();
    GLuint tex[] = {colour_tex, depth_tex, hu_tex, grad_tex, label_tex, occ_tex, tf_tex, label_colour_tex};
    for (GLuint t : tex)
      if (t) g.DeleteTextures(1, &t);
    if (fbo) g.DeleteFramebuffers(1, &fbo);
    if (vao) g.DeleteVertexArrays(1, &vao);
  }

  gl::ShaderProgram& program(bool packed_volume, bool labels, bool hide_exterior) {
    std::vector<std::string> defines;
    if (packed_volume) defines.push_back("PACKED");
    if (labels) defines.push_back("LABELS");
    if (hide_exterior) defines.push_back("HIDE_EXTERIOR");
    std::string key;
    for (const auto& d : defines) key += d + ";";
    auto& p = programs[key];
    if (!p) p = std::make_unique<gl::ShaderProgram>("fullscreen.vert", "raycast.frag", defines);
    return *p;
  }

  void ensure_framebuffer(int w, int h) {
    const gl::Api& g = gl::api();
    if (w == fb_width && h == fb_height) return;
    if (colour_tex) g.DeleteTextures(1, &colour_tex);
    if (depth_tex) g.DeleteTextures(1, &depth_tex);
    colour_tex = make_texture(GL_TEXTURE_2D, GL_NEAREST);
    g.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, nullptr);
    depth_tex = make_texture(GL_TEXTURE_2D, GL_NEAREST);
    g.TexImage2D(GL_TEXTURE_2D, 0, GL_R32F, w, h, 0, GL_RED, GL_FLOAT, nullptr);
    g.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    g.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour_tex, 0);
    g.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, depth_tex, 0);
    const GLenum bufs[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    g.DrawBuffers(2, bufs);
    const GLenum status = g.CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("the ray caster's framebuffer is incomplete (status " + std::to_string(status) + ")");
    gl::check_error("framebuffer " + std::to_string(w) + "x" + std::to_string(h));
    fb_width = w;
    fb_height = h;
  }

  // The organ colours per voxel (label_colour_volume), built when the colours differ from the last
  // built for this volume: once per volume in practice.
  void upload_label_colours(const LabelColours& c) {
    if (colours_uploaded && *colours_uploaded == c.rgba) return;
    const gl::Api& g = gl::api();
    if (label_colour_tex) g.DeleteTextures(1, &label_colour_tex);
    label_colour_tex = make_texture(GL_TEXTURE_3D, GL_LINEAR);
    g.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (labels->empty()) {
      const uint8_t zero[4] = {0, 0, 0, 0};
      g.TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA8, 1, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    } else {
      const std::vector<uint8_t> rgba = label_colour_volume(*labels, c);
      const auto& d = geometry.dims;
      g.TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA8, GLsizei(d[0]), GLsizei(d[1]), GLsizei(d[2]), 0, GL_RGBA,
                   GL_UNSIGNED_BYTE, rgba.data());
    }
    gl::check_error("label colour upload");
    colours_uploaded = c.rgba;
  }

  void upload_occupancy(const RenderSettings& s) {
    const OccupancyKey key = occupancy_key(s);
    if (occ_key && *occ_key == key) return;
    const OccupancyGrid occ = occupancy(ranges, s.tf, s.hide_exterior_air);
    const gl::Api& g = gl::api();
    if (occ_tex) g.DeleteTextures(1, &occ_tex);
    occ_tex = make_texture(GL_TEXTURE_3D, GL_NEAREST);
    g.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    g.TexImage3D(GL_TEXTURE_3D, 0, GL_R8UI, GLsizei(occ.blocks[0]), GLsizei(occ.blocks[1]), GLsizei(occ.blocks[2]), 0,
                 GL_RED_INTEGER, GL_UNSIGNED_BYTE, occ.occupied.data());
    gl::check_error("occupancy upload");
    occ_key = key;
  }
};

GlRayCaster::GlRayCaster(GlContext& context) : impl_(std::make_unique<Impl>(context)) {}
GlRayCaster::~GlRayCaster() = default;

const std::string& GlRayCaster::hu_format() const { return impl_->hu_format; }

void GlRayCaster::set_volume(const RenderVolume& v, bool force_float) {
  Impl& m = *impl_;
  m.ctx.make_current();
  const gl::Api& g = gl::api();
  std::optional<RenderVolume> smoothed;
  const RenderVolume& viewed = volume_as_viewed(v, smoothed, /*with_labels=*/false);
  const auto& d = viewed.geometry.dims;
  const int max3d = m.ctx.info().max_3d_texture_size;
  for (int a = 0; a < 3; ++a)
    if (d[a] > max3d)
      throw InputError("the volume's " + std::to_string(d[a]) + " voxels along axis " + std::to_string(a) +
                       " exceed this OpenGL's 3-D texture limit of " + std::to_string(max3d));
  g.PixelStorei(GL_UNPACK_ALIGNMENT, 1);  // 16-bit rows need not be 4-byte aligned
  if (m.hu_tex) g.DeleteTextures(1, &m.hu_tex);
  if (m.grad_tex) g.DeleteTextures(1, &m.grad_tex);
  m.grad_tex = 0;
  m.hu_tex = make_texture(GL_TEXTURE_3D, GL_LINEAR);
  // SNORM maps s to s/32767 exactly for s in ±32767 and filters in floating point.
  m.packed = v.hu_is_int16 && !force_float;
  const std::vector<int16_t> grad = voxel_gradients(viewed, m.packed);
  if (m.packed) {  // (HU, gx, gy, gz): one fetch per shaded sample
    g.TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA16_SNORM, GLsizei(d[0]), GLsizei(d[1]), GLsizei(d[2]), 0, GL_RGBA,
                 GL_SHORT, grad.data());
    m.hu_scale = 32767.0f;
    m.hu_format = "rgba16_snorm";
  } else {
    g.TexImage3D(GL_TEXTURE_3D, 0, GL_R32F, GLsizei(d[0]), GLsizei(d[1]), GLsizei(d[2]), 0, GL_RED, GL_FLOAT,
                 viewed.hu.data());
    m.grad_tex = make_texture(GL_TEXTURE_3D, GL_LINEAR);
    g.TexImage3D(GL_TEXTURE_3D, 0, GL_RGBA16_SNORM, GLsizei(d[0]), GLsizei(d[1]), GLsizei(d[2]), 0, GL_RGBA,
                 GL_SHORT, grad.data());
    m.hu_scale = 1.0f;
    m.hu_format = "r32f";
  }
  gl::check_error("CT upload");
  if (m.label_tex) g.DeleteTextures(1, &m.label_tex);
  m.label_tex = make_texture(GL_TEXTURE_3D, GL_NEAREST);
  // On a coarser grid volume_as_viewed resampled the labels; on the CT's it left them in v.
  const bool resampled = smoothed && !smoothed->labels.empty();   // asked without labels: only then
  m.resampled_labels = resampled ? std::move(smoothed->labels) : std::vector<uint16_t>{};
  m.labels = resampled ? &m.resampled_labels : &v.labels;
  if (!m.labels->empty()) {
    g.TexImage3D(GL_TEXTURE_3D, 0, GL_R16UI, GLsizei(d[0]), GLsizei(d[1]), GLsizei(d[2]), 0, GL_RED_INTEGER,
                 GL_UNSIGNED_SHORT, m.labels->data());
  } else {
    const uint16_t zero = 0;
    g.TexImage3D(GL_TEXTURE_3D, 0, GL_R16UI, 1, 1, 1, 0, GL_RED_INTEGER, GL_UNSIGNED_SHORT, &zero);
  }
  gl::check_error("label upload");
  m.geometry = viewed.geometry;
  m.w2i = viewed.world_to_index();
  m.ranges = block_ranges(viewed, *m.labels);
  m.occ_key.reset();
  m.colours_uploaded.reset();
  m.have_volume = true;
  log::debug("GL ray caster: volume " + std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" +
             std::to_string(d[2]) + " as " + m.hu_format +
             (d != v.geometry.dims ? " (the views' grid, coarser than the CT's " + std::to_string(v.geometry.dims[0]) +
                                         "x" + std::to_string(v.geometry.dims[1]) + "x" +
                                         std::to_string(v.geometry.dims[2]) + ")"
                                   : std::string()));
}

std::vector<int16_t> GlRayCaster::read_gradient_texture() {
  Impl& m = *impl_;
  if (!m.have_volume) throw std::logic_error("GlRayCaster::read_gradient_texture before set_volume");
  m.ctx.make_current();
  const gl::Api& g = gl::api();
  std::vector<int16_t> t(std::size_t(m.geometry.voxel_count()) * 4);
  g.BindTexture(GL_TEXTURE_3D, m.packed ? m.hu_tex : m.grad_tex);
  g.PixelStorei(GL_PACK_ALIGNMENT, 1);
  g.GetTexImage(GL_TEXTURE_3D, 0, GL_RGBA, GL_SHORT, t.data());
  gl::check_error("gradient texture read back");
  std::vector<int16_t> out(std::size_t(m.geometry.voxel_count()) * 3);
  const int first = m.packed ? 1 : 0;
  for (std::size_t n = 0; n < out.size() / 3; ++n)
    for (int c = 0; c < 3; ++c) out[3 * n + c] = t[4 * n + first + c];
  return out;
}

RenderImage GlRayCaster::render(const ViewCamera& cam, const RenderSettings& s) {
  Impl& m = *impl_;
  if (!m.have_volume) throw std::logic_error("GlRayCaster::render before set_volume");
  if (!(s.step_mm > 0.0)) throw InputError("the ray step must be positive");
  m.ctx.make_current();
  const gl::Api& g = gl::api();
  m.ensure_framebuffer(cam.width, cam.height);
  m.upload_occupancy(s);

  // Transfer function and label colour tables (small; uploaded every frame).
  if (!m.tf_tex) m.tf_tex = make_texture(GL_TEXTURE_2D, GL_LINEAR);
  g.BindTexture(GL_TEXTURE_2D, m.tf_tex);
  std::vector<float> tf = s.tf.table_rgba(kTfTableHuMin, kTfTableSize);
  const double exponent = s.step_mm / kOpacityUnitMm;  // opacity correction, tabulated (model step 2)
  for (std::size_t i = 3; i < tf.size(); i += 4)
    tf[i] = float(1.0 - std::pow(1.0 - std::min(double(tf[i]), 1.0), exponent));
  g.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, kTfTableSize, 1, 0, GL_RGBA, GL_FLOAT, tf.data());
  gl::check_error("table upload");
  if (s.show_labels) m.upload_label_colours(s.label_colours);

  const gl::ShaderProgram& prog = m.program(m.packed, s.show_labels, s.hide_exterior_air);
  prog.use();
  const GLuint textures[] = {m.hu_tex, m.grad_tex, m.label_tex, m.occ_tex, m.tf_tex, s.show_labels ? m.label_colour_tex : 0};
  const GLenum targets[] = {GL_TEXTURE_3D, GL_TEXTURE_3D, GL_TEXTURE_3D, GL_TEXTURE_3D, GL_TEXTURE_2D, GL_TEXTURE_3D};
  const char* names[] = {"u_vol", "u_grad", "u_labels", "u_occupancy", "u_tf", "u_label_colour"};
  for (int i = 0; i < 6; ++i) {
    if (!textures[i]) continue;
    g.ActiveTexture(GL_TEXTURE0 + i);
    g.BindTexture(targets[i], textures[i]);
    g.Uniform1i(prog.uniform(names[i]), i);
  }
  g.ActiveTexture(GL_TEXTURE0);
  auto u3 = [&](const char* n, const Vec3& v) { g.Uniform3f(prog.uniform(n), float(v.x()), float(v.y()), float(v.z())); };
  auto u1 = [&](const char* n, double v) { g.Uniform1f(prog.uniform(n), float(v)); };
  auto i1 = [&](const char* n, int v) { g.Uniform1i(prog.uniform(n), v); };
  const auto& d = m.geometry.dims;
  u3("u_inv_dims", Vec3(1.0 / double(d[0]), 1.0 / double(d[1]), 1.0 / double(d[2])));
  g.Uniform3i(prog.uniform("u_dims_i"), GLint(d[0]), GLint(d[1]), GLint(d[2]));
  float w2i[9];
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) w2i[3 * c + r] = float(m.w2i(r, c));  // column-major
  g.UniformMatrix3fv(prog.uniform("u_world_to_index"), 1, GL_FALSE, w2i);
  u3("u_origin_mm", m.geometry.origin_mm);
  u1("u_hu_scale", m.hu_scale);
  u1("u_grad_scale", 32767.0 * kGradientHalf);
  u1("u_tf_hu_min", kTfTableHuMin);
  u1("u_tf_size", kTfTableSize);
  g.Uniform3i(prog.uniform("u_blocks"), GLint(m.ranges.blocks[0]), GLint(m.ranges.blocks[1]),
              GLint(m.ranges.blocks[2]));
  u1("u_block", kOccupancyBlock);
  u3("u_cam_pos", cam.position_mm);
  u3("u_forward", cam.forward);
  u3("u_right", cam.right);
  u3("u_up", cam.up);
  i1("u_fisheye", cam.lens == Lens::Fisheye ? 1 : 0);
  u1("u_half_fov", cam.fov_deg * 3.14159265358979323846 / 360.0);
  u1("u_near", cam.near_mm);
  g.Uniform2f(prog.uniform("u_image"), float(cam.width), float(cam.height));
  u1("u_step", s.step_mm);
  i1("u_jitter", s.jitter ? 1 : 0);
  g.Uniform1ui(prog.uniform("u_seed"), s.jitter_seed);
  u1("u_label_opacity", s.label_opacity);
  u1("u_ambient", s.ambient);
  u1("u_diffuse", s.diffuse);
  u1("u_specular", s.specular);
  u1("u_shininess", s.shininess);
  u1("u_falloff", s.light_falloff_mm);
  g.Uniform2f(prog.uniform("u_pixel_offset"), float(s.pixel_offset_x), float(s.pixel_offset_y));
  u1("u_vignetting", s.vignetting_power);
  gl::check_error("uniforms");

  g.BindFramebuffer(GL_FRAMEBUFFER, m.fbo);
  g.Viewport(0, 0, cam.width, cam.height);
  g.BindVertexArray(m.vao);  // core profile: a VAO must be bound even without attributes
  g.DrawArrays(GL_TRIANGLES, 0, 3);
  gl::check_error("ray casting draw");

  RenderImage img;
  img.width = cam.width;
  img.height = cam.height;
  const std::size_t npx = std::size_t(cam.width) * cam.height;
  std::vector<float> rgba(npx * 4), depth(npx);
  g.PixelStorei(GL_PACK_ALIGNMENT, 4);
  g.ReadBuffer(GL_COLOR_ATTACHMENT0);
  g.ReadPixels(0, 0, cam.width, cam.height, GL_RGBA, GL_FLOAT, rgba.data());
  g.ReadBuffer(GL_COLOR_ATTACHMENT1);
  g.ReadPixels(0, 0, cam.width, cam.height, GL_RED, GL_FLOAT, depth.data());
  gl::check_error("read back");
  // GL rows come bottom-up; images here are top row first.
  img.rgba.resize(npx * 4);
  img.depth_mm.resize(npx);
  for (int y = 0; y < cam.height; ++y) {
    const std::size_t src = std::size_t(cam.height - 1 - y) * cam.width, dst = std::size_t(y) * cam.width;
    std::copy_n(rgba.begin() + 4 * src, 4 * cam.width, img.rgba.begin() + 4 * dst);
    for (int x = 0; x < cam.width; ++x) {
      const float dm = depth[src + x];
      img.depth_mm[dst + x] = dm < 0.0f ? std::numeric_limits<float>::infinity() : dm;
    }
  }
  return img;
}

}  // namespace pneumo
