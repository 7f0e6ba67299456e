// The laparoscope's ray caster (method.md §8): one ray per pixel from the camera model, front-to-back
// compositing with opacity correction, early termination, empty-space skipping, Phong shading with
// a headlight, organ labels. The model is stated in render/render_settings.h; the CPU reference
// (render/ray_cast_ref.cpp) implements the same model and the tests compare the two.
#version 330 core
// Compile-time variants (prepended #defines) instead of uniform branches: llvmpipe runs both
// sides of every `if` under lane masks and never jumps over a block, so a texture fetch behind a
// false uniform condition still costs its full price in every loop iteration.
//   PACKED         u_vol holds (HU, gradient) in one RGBA16_SNORM texture, so a shaded sample is
//                  one trilinear fetch (integer HU); else u_vol is HU (R32F) and u_grad the gradient
//   LABELS         organ colours blended (show_labels), trilinear from premultiplied per-voxel colours
//   HIDE_EXTERIOR  samples in exterior air contribute nothing (hide_exterior_air)

layout(location = 0) out vec4 out_colour;  // premultiplied RGB over black, accumulated opacity
layout(location = 1) out float out_depth;  // mm to the first surface, -1 where there is none

uniform sampler3D u_vol;         // PACKED: (HU, gx, gy, gz)/32767 (RGBA16_SNORM); else HU (R32F)
#ifndef PACKED
uniform sampler3D u_grad;        // (gx, gy, gz, 0)/32767 (RGBA16_SNORM)
#endif
uniform usampler3D u_labels;     // label ids, nearest (texelFetch): exterior air
uniform sampler3D u_label_colour; // premultiplied organ colour per voxel (RGBA8, trilinear)
uniform usampler3D u_occupancy;  // 1 = block may hold something visible
uniform sampler2D u_tf;          // RGB and step-corrected opacity per HU, u_tf_size entries from u_tf_hu_min

uniform vec3 u_inv_dims;         // 1 / voxels per axis
uniform ivec3 u_dims_i;          // voxels per axis
uniform mat3 u_world_to_index;   // (direction·spacing)⁻¹
uniform vec3 u_origin_mm;        // world position of voxel (0,0,0)
uniform float u_hu_scale;        // HU per texture unit: 32767 (PACKED) or 1
uniform float u_grad_scale;      // HU per voxel index per texture unit: 32767 / 2
uniform float u_tf_hu_min;
uniform float u_tf_size;
uniform ivec3 u_blocks;
uniform float u_block;           // voxels per occupancy block

uniform vec3 u_cam_pos, u_forward, u_right, u_up;
uniform int u_fisheye;
uniform float u_half_fov;        // radians
uniform float u_near;
uniform vec2 u_image;            // width, height

uniform float u_step;            // mm
uniform int u_jitter;
uniform uint u_seed;
uniform float u_label_opacity;
uniform float u_ambient, u_diffuse, u_specular, u_shininess, u_falloff;
uniform vec2 u_pixel_offset;     // model step 1: the ray through the pixel centre moved by this
uniform float u_vignetting;      // model step 6: colour × (forward·dir)^n; 0: none

const uint kExteriorAir = 65535u;
const float kEarlyTermination = 0.99;
const float kDepthOpacity = 0.5;
const float kFlatGradient = 1e-3;
const int kEntryBisections = 6;   // render_settings.h, model step 2b: the entry found to Δs/64

vec4 tf_at(float h) { return textureLod(u_tf, vec2((h - u_tf_hu_min + 0.5) / u_tf_size, 0.5), 0.0); }

float hu_at(vec3 idx) { return textureLod(u_vol, (idx + 0.5) * u_inv_dims, 0.0).r * u_hu_scale; }

uint label_at(vec3 idx) {
  ivec3 v = clamp(ivec3(floor(idx + 0.5)), ivec3(0), u_dims_i - 1);
  return texelFetch(u_labels, v, 0).r;
}

// One sample at p (model step 2): its label, its volume texel (HU and, packed, the gradient) and its transfer
// function entry; false when it contributes nothing.
bool sample_at(vec3 p, out uint id, out vec4 v, out vec4 tf) {
  id = 0u;
#ifdef HIDE_EXTERIOR
  id = label_at(p);
#endif
  v = vec4(0.0);
  tf = vec4(0.0);
#ifdef HIDE_EXTERIOR
  if (id == kExteriorAir) return false;
#endif
  v = textureLod(u_vol, (p + 0.5) * u_inv_dims, 0.0);
  tf = tf_at(v.r * u_hu_scale);
  return tf.a > 0.0;
}

// Whether p contributes nothing, with the fetches the entry's bisection needs only.
bool clear_at(vec3 p) {
#ifdef HIDE_EXTERIOR
  if (label_at(p) == kExteriorAir) return true;
#endif
  return tf_at(hu_at(p)).a <= 0.0;
}

float jitter_offset(uint px, uint py, uint seed) {
  uint h = (px * 73856093u) ^ (py * 19349663u) ^ (seed * 83492791u);
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return float(h >> 8) * (1.0 / 16777216.0);
}

// Ray parameter interval inside the axis-aligned box [lo, hi] (index space); t0 > t1 when missed.
vec2 clip_box(vec3 o, vec3 d, vec3 lo, vec3 hi) {
  vec3 inv = 1.0 / mix(d, vec3(1e-20), equal(d, vec3(0.0)));
  vec3 ta = (lo - o) * inv, tb = (hi - o) * inv;
  vec3 tmin = min(ta, tb), tmax = max(ta, tb);
  return vec2(max(max(tmin.x, tmin.y), tmin.z), min(min(tmax.x, tmax.y), tmax.z));
}

void main() {
  out_colour = vec4(0.0);
  out_depth = -1.0;
  // Pixel centre with the top row first, as the CPU reference counts them.
  vec2 centre = vec2(gl_FragCoord.x, u_image.y - gl_FragCoord.y);
  uvec2 pixel = uvec2(centre);   // the pixel's own index: the jitter hash does not move with the offset
  vec2 pix = centre + u_pixel_offset;
  float x = 2.0 * pix.x / u_image.x - 1.0;
  float y = (1.0 - 2.0 * pix.y / u_image.y) * u_image.y / u_image.x;
  vec3 dir;
  if (u_fisheye == 0) {
    dir = normalize(u_forward + tan(u_half_fov) * (x * u_right + y * u_up));
  } else {
    float r = sqrt(x * x + y * y);
    if (r > 1.0) return;  // outside the image circle
    float theta = r * u_half_fov;
    dir = r > 0.0 ? normalize(cos(theta) * u_forward + sin(theta) / r * (x * u_right + y * u_up)) : u_forward;
  }

  vec3 o = u_world_to_index * (u_cam_pos - u_origin_mm);
  vec3 d = u_world_to_index * dir;  // index units per mm
  vec3 dims = vec3(u_dims_i);
  vec2 tc = clip_box(o, d, vec3(0.0), dims - 1.0);
  float t_lo = max(tc.x, u_near), t_hi = tc.y;
  if (!(t_lo <= t_hi)) return;
  float j = u_jitter != 0 ? jitter_offset(pixel.x, pixel.y, u_seed) : 0.0;
  int k = max(0, int(ceil((t_lo - u_near) / u_step - j)));

  // Loop invariants of the block jump: the far face of a block along each axis, and 1/d.
  vec3 inv_d = 1.0 / mix(d, vec3(1e-20), equal(d, vec3(0.0)));
  vec3 far_face = step(vec3(0.0), d) * u_block;
  mat3 index_to_world_t = transpose(u_world_to_index);
  float inv_falloff2 = 1.0 / (u_falloff * u_falloff);
  vec3 C = vec3(0.0);
  float A = 0.0;
  float t_clear = -1.0;   // the last t known to contribute nothing, while no sample since has; else -1
  for (;; ++k) {
    float t = u_near + (float(k) + j) * u_step;
    if (t > t_hi) break;
    if (t < t_lo) continue;
    vec3 p = o + t * d;
    // Empty-space skipping, in a loop of its own so that a jump costs only the occupancy fetch:
    // jump to the first sample at or beyond the far face of each empty block.
    ivec3 b = clamp(ivec3(p / u_block), ivec3(0), u_blocks - 1);  // p ≥ 0: truncation is floor
    bool jumped = false;
    while (texelFetch(u_occupancy, b, 0).r == 0u) {
      jumped = true;
      vec3 te = (vec3(b) * u_block + far_face - o) * inv_d;
      float t_exit = min(min(te.x, te.y), te.z);
      k = max(k + 1, int(ceil((t_exit - u_near) / u_step - j)));
      t = u_near + (float(k) + j) * u_step;
      if (t > t_hi) break;
      p = o + t * d;
      b = clamp(ivec3(p / u_block), ivec3(0), u_blocks - 1);
    }
    if (t > t_hi) break;
    // The lattice point before t lay in an empty block: as the reference, which samples it, sees it clear.
    if (jumped) t_clear = t - u_step;
    uint id;
    vec4 v, tf;
    if (!sample_at(p, id, v, tf)) { t_clear = t; continue; }
    if (t_clear >= 0.0) {
      // Entering matter from clear space (model step 2b): bisect for where the opacity begins and take the
      // first sample half a step past it, so a surface's samples sit where it is, not where the lattice fell.
      float lo = t_clear, hi = t;
      for (int r = 0; r < kEntryBisections; ++r) {
        float mid = 0.5 * (lo + hi);
        if (clear_at(o + mid * d)) lo = mid; else hi = mid;
      }
      t = hi + 0.5 * u_step;   // the first sample half a step in: a midpoint sum from the entry on
      j = (t - u_near) / u_step - float(k);   // the following samples a step apart from here
      if (t > t_hi) break;
      p = o + t * d;
      if (!sample_at(p, id, v, tf)) { t_clear = t; continue; }   // a layer thinner than half a step
    }
    t_clear = -1.0;
    float a = tf.a;  // already corrected for the step
    vec3 c = tf.rgb;
#ifdef LABELS
    vec4 lc = textureLod(u_label_colour, (p + 0.5) * u_inv_dims, 0.0);
    c = c * (1.0 - u_label_opacity * lc.a) + u_label_opacity * lc.rgb;
#endif
#ifdef PACKED
    vec3 g_idx = v.gba * u_grad_scale;
#else
    vec3 g_idx = textureLod(u_grad, (p + 0.5) * u_inv_dims, 0.0).rgb * u_grad_scale;
#endif
    vec3 g = index_to_world_t * g_idx;
    float glen2 = dot(g, g);
    bool surface = glen2 >= kFlatGradient * kFlatGradient;
    float ndl = min(abs(dot(g, dir)) * inversesqrt(max(glen2, 1e-30)), 1.0);
    float diffuse = surface ? ndl : 1.0;
    float specular = surface ? pow(ndl, u_shininess) : 0.0;
    float att = 1.0 / (1.0 + t * t * inv_falloff2);
    vec3 shaded = c * (u_ambient + u_diffuse * diffuse * att) + vec3(u_specular * specular * att);
    C += (1.0 - A) * a * shaded;
    A += (1.0 - A) * a;
    if (A >= kDepthOpacity && out_depth < 0.0) out_depth = t;
    if (A > kEarlyTermination) break;
  }
  if (u_vignetting > 0.0) C *= pow(max(dot(u_forward, dir), 0.0), u_vignetting);
  out_colour = vec4(clamp(C, 0.0, 1.0), A);
}
