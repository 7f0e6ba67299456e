// The tetrahedral finite elements on the device, float32: element states, forces, the matrix-free
// stiffness product and its diagonal blocks. Equal within float rounding to the double-precision
// reference (host/solve/fem_element.cpp, host/solve/fem_force_field.cpp); the laws and the mean
// dilatation are explained there.
//
// Precision: the state is node displacements u (float4), as in msd_forces.cl, and each element works
// with H = D_u D_m⁻¹, so F = I + H is never formed from large positions. The co-rotational polar
// decomposition diagonalises C − I = H + Hᵀ + HᵀH (not C), and the neo-Hookean J − 1 and Ī₁ − 3 are
// expanded in H, so small strains keep their relative precision instead of drowning in the 1 of I.
//
// Layout per tetrahedron: D_m⁻¹ (9 floats, row-major), (V₀, μ, κ, k₂) as a float4, the fibre family
// (a₀, k₁) as a float4 (k₁ = 0: none); the state (kStateFloats, below). Per group of the mean dilatation: [begin, end) in the group's list of tetrahedra and
// 1/Σ κ_t V_t. Per node: compressed rows of (tetrahedron × 8 + vertex), as host/mesh/adjacency.h.

// State offsets: F (9), A (9: R, or F⁻ᵀ), B (9: the co-rotational (tr S·I − S)⁻¹), then e, J^{−2/3},
// I₁, e^{b(Ī₁−3)}, valid, the deviatoric energy density, and for a tetrahedron with fibres 2ψ' and
// 4ψ'' of the fibre term and F a₀ (S_FIB: computed once per state, not per stiffness product). The
// stride and the two offsets the host reads (e for the group average, ψ for the energy) come from the
// host as build options
// (fem_force_field_cl.cpp), so the layout is written once on each side of what they share.
#if !defined(kStateFloats) || !defined(S_E) || !defined(S_PSI)
#error "fem_forces.cl needs -DkStateFloats, -DS_E and -DS_PSI (fem_force_field_cl.cpp)"
#endif
#define S_F 0
#define S_A 9
#define S_B 18
#define S_J23 (S_E + 1)
#define S_I1 (S_E + 2)
#define S_EXP (S_E + 3)
#define S_VALID (S_E + 4)
#define S_FIB (S_PSI + 1)
#if S_FIB + 5 > kStateFloats
#error "the fibre terms do not fit the state"
#endif

typedef struct { float m[9]; } mat3;   // row-major

inline mat3 m_zero(void) { mat3 r; for (int i = 0; i < 9; ++i) r.m[i] = 0.0f; return r; }
inline mat3 m_identity(void) { mat3 r = m_zero(); r.m[0] = r.m[4] = r.m[8] = 1.0f; return r; }
inline mat3 m_load(__global const float* p) { mat3 r; for (int i = 0; i < 9; ++i) r.m[i] = p[i]; return r; }
inline void m_store(__global float* p, mat3 a) { for (int i = 0; i < 9; ++i) p[i] = a.m[i]; }
inline mat3 m_add(mat3 a, mat3 b) { for (int i = 0; i < 9; ++i) a.m[i] += b.m[i]; return a; }
inline mat3 m_sub(mat3 a, mat3 b) { for (int i = 0; i < 9; ++i) a.m[i] -= b.m[i]; return a; }
inline mat3 m_scale(mat3 a, float s) { for (int i = 0; i < 9; ++i) a.m[i] *= s; return a; }
inline mat3 m_axpy(float s, mat3 a, mat3 b) { for (int i = 0; i < 9; ++i) b.m[i] += s * a.m[i]; return b; }
inline float m_ddot(mat3 a, mat3 b) { float s = 0.0f; for (int i = 0; i < 9; ++i) s += a.m[i] * b.m[i]; return s; }
inline mat3 m_t(mat3 a) {
  mat3 r;
  for (int i = 0; i < 3; ++i) for (int j = 0; j < 3; ++j) r.m[3 * i + j] = a.m[3 * j + i];
  return r;
}
inline mat3 m_mul(mat3 a, mat3 b) {
  mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[3 * i + j] = a.m[3 * i] * b.m[j] + a.m[3 * i + 1] * b.m[3 + j] + a.m[3 * i + 2] * b.m[6 + j];
  return r;
}
inline float3 m_col(mat3 a, int j) { return (float3)(a.m[j], a.m[3 + j], a.m[6 + j]); }
inline float3 m_vec(mat3 a, float3 v) {
  return (float3)(a.m[0] * v.x + a.m[1] * v.y + a.m[2] * v.z, a.m[3] * v.x + a.m[4] * v.y + a.m[5] * v.z,
                  a.m[6] * v.x + a.m[7] * v.y + a.m[8] * v.z);
}
inline mat3 m_from_cols(float3 a, float3 b, float3 c) {
  mat3 r;
  r.m[0] = a.x; r.m[1] = b.x; r.m[2] = c.x;
  r.m[3] = a.y; r.m[4] = b.y; r.m[5] = c.y;
  r.m[6] = a.z; r.m[7] = b.z; r.m[8] = c.z;
  return r;
}
inline mat3 m_cross(float3 v) {   // [v]×
  mat3 r = m_zero();
  r.m[1] = -v.z; r.m[2] = v.y; r.m[3] = v.z; r.m[5] = -v.x; r.m[6] = -v.y; r.m[7] = v.x;
  return r;
}
inline float m_det(mat3 a) { return dot(m_col(a, 0), cross(m_col(a, 1), m_col(a, 2))); }
// det(I + H) − 1 = tr H + ½((tr H)² − tr H²) + det H.
inline float det_identity_plus_minus_one(mat3 h) {
  const float tr = h.m[0] + h.m[4] + h.m[8];
  const float tr2 = m_ddot(h, m_t(h));   // tr(H H) = Σ H_ij H_ji
  return tr + 0.5f * (tr * tr - tr2) + m_det(h);
}
// (A⁻¹)ᵀ = cof(A) / det A, cof's columns the cross products of A's columns.
inline mat3 m_inverse_t(mat3 a, float det) {
  const float3 c0 = m_col(a, 0), c1 = m_col(a, 1), c2 = m_col(a, 2);
  return m_scale(m_from_cols(cross(c1, c2), cross(c2, c0), cross(c0, c1)), 1.0f / det);
}

// Eigen-decomposition of a symmetric matrix by cyclic Jacobi rotations: a = V diag(w) Vᵀ.
inline void symmetric_eigen(mat3 a, mat3* v, float3* w) {
  mat3 V = m_identity();
  for (int sweep = 0; sweep < 8; ++sweep) {
    const float off = a.m[1] * a.m[1] + a.m[2] * a.m[2] + a.m[5] * a.m[5];
    const float diag = a.m[0] * a.m[0] + a.m[4] * a.m[4] + a.m[8] * a.m[8];
    if (!(off > 1e-14f * diag)) break;   // off-diagonal below float rounding
    for (int pq = 0; pq < 3; ++pq) {
      const int p = pq == 2 ? 1 : 0, q = pq == 0 ? 1 : 2;
      const float apq = a.m[3 * p + q];
      if (apq == 0.0f) continue;
      const float theta = (a.m[3 * q + q] - a.m[3 * p + p]) / (2.0f * apq);
      const float t = sign(theta) / (fabs(theta) + sqrt(theta * theta + 1.0f));
      const float tt = theta == 0.0f ? 1.0f : t;
      const float c = rsqrt(tt * tt + 1.0f), s = tt * c;
      // a ← Jᵀ a J with J the rotation in the (p, q) plane.
      mat3 J = m_identity();
      J.m[3 * p + p] = c; J.m[3 * q + q] = c; J.m[3 * p + q] = s; J.m[3 * q + p] = -s;
      a = m_mul(m_t(J), m_mul(a, J));
      a.m[3 * p + q] = a.m[3 * q + p] = 0.0f;
      V = m_mul(V, J);
    }
  }
  *v = V;
  *w = (float3)(a.m[0], a.m[4], a.m[8]);
}

// The co-rotational state from H: F = I + H = R S (fem_element.cpp: R a rotation, the reflection of
// an inverted element in the smallest stretch), (tr S·I − S)⁻¹ floored as there, e = tr S − 3.
inline void corotational_state(mat3 h, __global float* st) {
  const mat3 F = m_add(m_identity(), h);
  mat3 V;
  float3 w;
  symmetric_eigen(m_add(m_add(h, m_t(h)), m_mul(m_t(h), h)), &V, &w);   // C − I
  // Sort descending (the stretches σ_i = √(1 + w_i)).
  float wv[3] = {w.x, w.y, w.z};
  float3 vc[3] = {m_col(V, 0), m_col(V, 1), m_col(V, 2)};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2 - i; ++j)
      if (wv[j] < wv[j + 1]) {
        const float tw = wv[j]; wv[j] = wv[j + 1]; wv[j + 1] = tw;
        const float3 tv = vc[j]; vc[j] = vc[j + 1]; vc[j + 1] = tv;
      }
  if (dot(vc[0], cross(vc[1], vc[2])) < 0.0f) vc[2] = -vc[2];   // V a rotation
  // σ − 1 = w / (√(1 + w) + 1), accurate for small w.
  float sm1[3];
  for (int i = 0; i < 3; ++i) sm1[i] = wv[i] / (sqrt(fmax(1.0f + wv[i], 0.0f)) + 1.0f);
  const float3 f0 = m_vec(F, vc[0]), f1 = m_vec(F, vc[1]), f2 = m_vec(F, vc[2]);
  const float3 u0 = normalize(f0);
  const float3 u1 = normalize(f1 - dot(u0, f1) * u0);
  const float3 u2 = cross(u0, u1);
  // The smallest stretch keeps its sign: negative for an inverted element.
  const float s2 = dot(u2, f2);
  sm1[2] = s2 - 1.0f;
  if (s2 > 0.0f) sm1[2] = wv[2] / (sqrt(fmax(1.0f + wv[2], 0.0f)) + 1.0f);
  const mat3 U = m_from_cols(u0, u1, u2), Vr = m_from_cols(vc[0], vc[1], vc[2]);
  const mat3 R = m_mul(U, m_t(Vr));
  const float sigma[3] = {1.0f + sm1[0], 1.0f + sm1[1], 1.0f + sm1[2]};
  const float ssum = sigma[0] + sigma[1] + sigma[2];
  mat3 inv_diag = m_zero();
  for (int i = 0; i < 3; ++i) {
    float sum = ssum - sigma[i];
    if (fabs(sum) < 1e-6f) sum = copysign(1e-6f, sum);
    inv_diag.m[4 * i] = 1.0f / sum;
  }
  m_store(st + S_F, F);
  m_store(st + S_A, R);
  m_store(st + S_B, m_mul(Vr, m_mul(inv_diag, m_t(Vr))));
  st[S_E] = sm1[0] + sm1[1] + sm1[2];
  st[S_VALID] = 1.0f;
}

// The neo-Hookean / Demiray state from H.
inline void neohookean_state(mat3 h, float b, __global float* st) {
  const mat3 F = m_add(m_identity(), h);
  const float jm1 = det_identity_plus_minus_one(h);
  const float J = 1.0f + jm1;
  const int valid = J > 0.0f && isfinite(J);
  m_store(st + S_F, F);
  st[S_VALID] = valid ? 1.0f : 0.0f;
  if (!valid) {
    st[S_E] = NAN;
    return;
  }
  const float lnJ = log1p(jm1);
  const float j23 = exp(-2.0f / 3.0f * lnJ);
  const float tr = h.m[0] + h.m[4] + h.m[8];
  // Ī₁ − 3 = 3(J^{−2/3} − 1) + J^{−2/3}(2 tr H + |H|²).
  const float bar_i1_m3 = 3.0f * expm1(-2.0f / 3.0f * lnJ) + j23 * (2.0f * tr + m_ddot(h, h));
  m_store(st + S_A, m_inverse_t(F, J));
  st[S_E] = lnJ;
  st[S_J23] = j23;
  st[S_I1] = m_ddot(F, F);
  st[S_EXP] = b > 0.0f ? exp(b * bar_i1_m3) : 1.0f;
  st[S_PSI] = bar_i1_m3;   // turned into the energy density by fem_states
}

inline mat3 rest_inverse(__global const float* dm_inv, int t) { return m_load(dm_inv + 9 * t); }

inline mat3 m_outer(float3 u, float3 v) {   // u ⊗ v
  return m_from_cols(u * v.x, u * v.y, u * v.z);
}

// The fibres' ψ_f, ψ' and ψ'' at F (fem_element.h; all zero in compression or without fibres), for
// fib = (a₀, k₁); *fa = F a₀. I₄ − 1 from F a₀ − a₀, so a small stretch keeps its relative precision.
inline float3 fibre_terms(mat3 F, float4 fib, float k2, float3* fa) {
  *fa = m_vec(F, fib.xyz);
  if (!(fib.w > 0.0f)) return (float3)(0.0f);
  const float3 h = *fa - fib.xyz;
  const float e = 2.0f * dot(fib.xyz, h) + dot(h, h);
  if (e < 0.0f) return (float3)(0.0f);
  const float x = k2 * e * e, ex = exp(x);
  const float energy = k2 > 0.0f ? fib.w * expm1(x) / (2.0f * k2) : 0.5f * fib.w * e * e;
  return (float3)(energy, fib.w * e * ex, fib.w * (1.0f + 2.0f * x) * ex);
}

// The fibre terms kept in the state (S_FIB): 2ψ', 4ψ'' and F a₀.
inline void store_fibre_terms(mat3 F, float4 fib, float k2, __global float* st) {
  float3 fa;
  const float3 t = fibre_terms(F, fib, k2, &fa);
  st[S_PSI] += t.x;
  st[S_FIB] = 2.0f * t.y;
  st[S_FIB + 1] = 4.0f * t.z;
  st[S_FIB + 2] = fa.x; st[S_FIB + 3] = fa.y; st[S_FIB + 4] = fa.z;
}

// P_f = 2ψ' (F a₀) ⊗ a₀.
inline mat3 fibre_piola(__global const float* st, float3 a0) {
  return m_outer(st[S_FIB] * (float3)(st[S_FIB + 2], st[S_FIB + 3], st[S_FIB + 4]), a0);
}

// δP_f = (2ψ' δF a₀ + 4ψ'' ((F a₀)·(δF a₀)) F a₀) ⊗ a₀.
inline mat3 fibre_dpiola(__global const float* st, mat3 dF, float3 a0) {
  const float3 fa = (float3)(st[S_FIB + 2], st[S_FIB + 3], st[S_FIB + 4]);
  const float3 dfa = m_vec(dF, a0);
  return m_outer(st[S_FIB] * dfa + st[S_FIB + 1] * dot(fa, dfa) * fa, a0);
}

// D_u of the vertices' displacements (or of a direction p).
inline mat3 edge_matrix_of(__global const float4* restrict u, int4 q) {
  const float3 a = u[q.x].xyz;
  return m_from_cols(u[q.y].xyz - a, u[q.z].xyz - a, u[q.w].xyz - a);
}

// law: 0 co-rotational, 1 neo-Hookean (b = 0) or Demiray (b > 0).
__kernel void fem_states(__global const float4* restrict u, __global const int4* restrict tets,
                         __global const float* restrict dm_inv, __global const float4* restrict tet_consts,
                         __global const float4* restrict fibre, const int law, const float b, const int n_tets,
                         __global float* restrict state) {
  const int t = get_global_id(0);
  if (t >= n_tets) return;
  const mat3 h = m_mul(edge_matrix_of(u, tets[t]), rest_inverse(dm_inv, t));
  __global float* st = state + kStateFloats * t;
  if (law == 0) {
    corotational_state(h, st);
    const mat3 d = m_sub(m_load(st + S_F), m_load(st + S_A));
    st[S_PSI] = tet_consts[t].y * m_ddot(d, d);
  } else {
    neohookean_state(h, b, st);
    if (st[S_VALID] == 0.0f) { st[S_PSI] = INFINITY; return; }
    const float x = st[S_PSI];
    st[S_PSI] = tet_consts[t].y * (b > 0.0f ? expm1(b * x) / (2.0f * b) : 0.5f * x);
  }
  if (fibre[t].w > 0.0f) store_fibre_terms(m_load(st + S_F), fibre[t], tet_consts[t].w, st);
}

// Group averages: out[g] = Σ_t w_t q_t / Σ_t w_t over the group's tetrahedra, q_t = per_tet[t * stride + offset].
__kernel void fem_group_average(__global const float* restrict per_tet, const int stride, const int offset,
                                __global const float* restrict weight, __global const int* restrict group_begin,
                                __global const int* restrict group_tets, __global const float* restrict inv_weight,
                                const int n_groups, __global float* restrict out) {
  const int g = get_global_id(0);
  if (g >= n_groups) return;
  float sum = 0.0f;
  for (int i = group_begin[g]; i < group_begin[g + 1]; ++i) {
    const int t = group_tets[i];
    sum += weight[t] * per_tet[t * stride + offset];
  }
  out[g] = sum * inv_weight[g];
}

inline mat3 dilatation_gradient(int law, __global const float* st) { return m_load(st + S_A); }

inline mat3 isochoric_i1_gradient(__global const float* st) {
  return m_scale(m_sub(m_scale(m_load(st + S_F), 2.0f), m_scale(m_load(st + S_A), 2.0f / 3.0f * st[S_I1])), st[S_J23]);
}

inline mat3 deviatoric_piola(int law, __global const float* st, float mu) {
  if (law == 0) return m_scale(m_sub(m_load(st + S_F), m_load(st + S_A)), 2.0f * mu);
  return m_scale(isochoric_i1_gradient(st), 0.5f * mu * st[S_EXP]);
}

// δR = R[ω]×, ω = (tr S·I − S)⁻¹ axial(RᵀδF − δFᵀR).
inline mat3 corotational_drotation(__global const float* st, mat3 dF) {
  const mat3 R = m_load(st + S_A);
  const mat3 A = m_mul(m_t(R), dF);
  const float3 ax = (float3)(A.m[7] - A.m[5], A.m[2] - A.m[6], A.m[3] - A.m[1]);
  return m_mul(R, m_cross(m_vec(m_load(st + S_B), ax)));
}

inline mat3 dilatation_dgradient(int law, __global const float* st, mat3 dF) {
  if (law == 0) return corotational_drotation(st, dF);
  const mat3 Fit = m_load(st + S_A);
  return m_scale(m_mul(Fit, m_mul(m_t(dF), Fit)), -1.0f);
}

inline mat3 deviatoric_dpiola(int law, __global const float* st, mat3 dF, float mu, float b) {
  if (law == 0) return m_scale(m_sub(dF, corotational_drotation(st, dF)), 2.0f * mu);
  const mat3 F = m_load(st + S_F), Fit = m_load(st + S_A);
  const float j23 = st[S_J23], i1 = st[S_I1], ex = st[S_EXP];
  const mat3 g = isochoric_i1_gradient(st);
  const mat3 d_inverse_t = m_scale(m_mul(Fit, m_mul(m_t(dF), Fit)), -1.0f);
  const float d_j23_over_j23 = -2.0f / 3.0f * m_ddot(Fit, dF);
  const float d_i1 = 2.0f * m_ddot(F, dF);
  const mat3 inner = m_sub(m_scale(dF, 2.0f), m_scale(m_add(m_scale(Fit, d_i1), m_scale(d_inverse_t, i1)), 2.0f / 3.0f));
  const mat3 dg = m_add(m_scale(g, d_j23_over_j23), m_scale(inner, j23));
  const float d_ex = b * ex * m_ddot(g, dF);
  return m_scale(m_add(m_scale(g, d_ex), m_scale(dg, ex)), 0.5f * mu);
}

// The four nodal forces of stress P: vertices 1–3 the columns of −V₀ P D_m⁻ᵀ, vertex 0 minus their sum.
inline void store_nodal_forces(mat3 P, mat3 dm_inverse, float volume, __global float4* out) {
  const mat3 Hf = m_scale(m_mul(P, m_t(dm_inverse)), -volume);
  const float3 f1 = m_col(Hf, 0), f2 = m_col(Hf, 1), f3 = m_col(Hf, 2);
  out[0] = (float4)(-(f1 + f2 + f3), 0.0f);
  out[1] = (float4)(f1, 0.0f);
  out[2] = (float4)(f2, 0.0f);
  out[3] = (float4)(f3, 0.0f);
}

__kernel void fem_forces(__global const float* restrict state, __global const float* restrict dm_inv,
                         __global const float4* restrict tet_consts, __global const float4* restrict fibre,
                         __global const int* restrict group_of_tet,
                         __global const float* restrict ebar, const int law, const int n_tets,
                         __global float4* restrict tet_force) {
  const int t = get_global_id(0);
  if (t >= n_tets) return;
  __global const float* st = state + kStateFloats * t;
  const float4 c = tet_consts[t];   // V₀, μ, κ, k₂
  mat3 Pd = deviatoric_piola(law, st, c.y);
  if (fibre[t].w > 0.0f) Pd = m_add(Pd, fibre_piola(st, fibre[t].xyz));
  const mat3 P = m_axpy(c.z * ebar[group_of_tet[t]], dilatation_gradient(law, st), Pd);
  store_nodal_forces(P, rest_inverse(dm_inv, t), c.x, tet_force + 4 * t);
}

// δF_t = D_p D_m⁻¹ and δe_t = G : δF_t (kept at dF[t * 10 + 9] for the group average).
__kernel void fem_dF(__global const float4* restrict p, __global const int4* restrict tets,
                     __global const float* restrict dm_inv, __global const float* restrict state, const int law,
                     const int n_tets, __global float* restrict dF) {
  const int t = get_global_id(0);
  if (t >= n_tets) return;
  const mat3 d = m_mul(edge_matrix_of(p, tets[t]), rest_inverse(dm_inv, t));
  m_store(dF + 10 * t, d);
  dF[10 * t + 9] = m_ddot(dilatation_gradient(law, state + kStateFloats * t), d);
}

// −K p per vertex: the nodal forces of δP_t = δP_d + κ(δē G + ē δG).
__kernel void fem_dforces(__global const float* restrict state, __global const float* restrict dm_inv,
                          __global const float4* restrict tet_consts, __global const float4* restrict fibre,
                          __global const int* restrict group_of_tet,
                          __global const float* restrict ebar, __global const float* restrict debar,
                          __global const float* restrict dF, const int law, const float b, const int n_tets,
                          __global float4* restrict tet_force) {
  const int t = get_global_id(0);
  if (t >= n_tets) return;
  __global const float* st = state + kStateFloats * t;
  const float4 c = tet_consts[t];
  const int g = group_of_tet[t];
  const mat3 d = m_load(dF + 10 * t);
  mat3 dP = deviatoric_dpiola(law, st, d, c.y, b);
  if (fibre[t].w > 0.0f) dP = m_add(dP, fibre_dpiola(st, d, fibre[t].xyz));
  dP = m_axpy(c.z * debar[g], dilatation_gradient(law, st), dP);
  dP = m_axpy(c.z * ebar[g], dilatation_dgradient(law, st, d), dP);
  store_nodal_forces(m_scale(dP, -1.0f), rest_inverse(dm_inv, t), c.x, tet_force + 4 * t);
}

// K_ii per tetrahedron and vertex from unit moves along each axis, with the tetrahedron's own
// dilatation (the preconditioner, as fem_force_field.cpp): 4 blocks of 3 columns (float4 each).
__kernel void fem_diagonal(__global const float* restrict state, __global const float* restrict dm_inv,
                           __global const float4* restrict tet_consts, __global const float4* restrict fibre,
                           const int law, const float b,
                           const int n_tets, __global float4* restrict blocks) {
  const int t = get_global_id(0);
  if (t >= n_tets) return;
  __global const float* st = state + kStateFloats * t;
  const float4 c = tet_consts[t];
  const mat3 Di = rest_inverse(dm_inv, t);
  const float3 r0 = (float3)(Di.m[0], Di.m[1], Di.m[2]), r1 = (float3)(Di.m[3], Di.m[4], Di.m[5]),
               r2 = (float3)(Di.m[6], Di.m[7], Di.m[8]);
  const float3 grads[4] = {-(r0 + r1 + r2), r0, r1, r2};
  const mat3 G = dilatation_gradient(law, st);
  const float e = st[S_E];
  for (int i = 0; i < 4; ++i)
    for (int a = 0; a < 3; ++a) {
      mat3 dF = m_zero();
      dF.m[3 * a + 0] = grads[i].x; dF.m[3 * a + 1] = grads[i].y; dF.m[3 * a + 2] = grads[i].z;
      mat3 dP = deviatoric_dpiola(law, st, dF, c.y, b);
      if (fibre[t].w > 0.0f) dP = m_add(dP, fibre_dpiola(st, dF, fibre[t].xyz));
      dP = m_axpy(c.z * m_ddot(G, dF), G, dP);
      dP = m_axpy(c.z * e, dilatation_dgradient(law, st, dF), dP);
      blocks[12 * t + 3 * i + a] = (float4)(c.x * m_vec(dP, grads[i]), 0.0f);
    }
}

// Per node: the elements' forces (tetrahedra, then pressure loads) and gravity, gathered in a fixed
// order through compressed rows of (element × 8 + vertex).
__kernel void fem_gather(__global const float4* restrict tet_force, __global const long* restrict tet_start,
                         __global const int* restrict tet_item, __global const float4* restrict load_force,
                         __global const long* restrict load_start, __global const int* restrict load_item,
                         const int with_loads, __global const float* restrict mass, const float4 gravity,
                         const int n_nodes, __global float4* restrict f) {
  const int n = get_global_id(0);
  if (n >= n_nodes) return;
  float3 sum = gravity.xyz * mass[n];
  for (long e = tet_start[n]; e < tet_start[n + 1]; ++e) {
    const int it = tet_item[e];
    sum += tet_force[4 * (it / 8) + it % 8].xyz;
  }
  if (with_loads)
    for (long e = load_start[n]; e < load_start[n + 1]; ++e) {
      const int it = load_item[e];
      sum += load_force[4 * (it / 8) + it % 8].xyz;
    }
  f[n] = (float4)(sum, 0.0f);
}

// The diagonal blocks per node: column a of block n at out[3n + a].
__kernel void fem_gather_diagonal(__global const float4* restrict blocks, __global const long* restrict tet_start,
                                  __global const int* restrict tet_item, const int n_nodes,
                                  __global float4* restrict out) {
  const int n = get_global_id(0);
  if (n >= n_nodes) return;
  float3 c0 = (float3)(0.0f), c1 = (float3)(0.0f), c2 = (float3)(0.0f);
  for (long e = tet_start[n]; e < tet_start[n + 1]; ++e) {
    const int it = tet_item[e];
    const int base = 12 * (it / 8) + 3 * (it % 8);
    c0 += blocks[base].xyz;
    c1 += blocks[base + 1].xyz;
    c2 += blocks[base + 2].xyz;
  }
  out[3 * n] = (float4)(c0, 0.0f);
  out[3 * n + 1] = (float4)(c1, 0.0f);
  out[3 * n + 2] = (float4)(c2, 0.0f);
}
