// lutbake anisotropic GGX area lights (Kt, Heitz, Dupuy & Narayanan 2022, "Bringing Linearly Transformed Cosines
// to Anisotropic GGX", I3D; their renderer's Sphere.glsl LtcMatrix_Tex3D / LtcMatrixAndNormalization). Needs
// docs/shaders/lutbake_ltc.glsl (lutbake_ltc_polygon, lutbake_ltc_edge) included first. GLSL 3.30.
//
// Files: kind ltc_aniso, format ktx2 or dds: <name>_t0, _t1, _t2 (.ktx2 / .dds), one 3D texture each (preset
// ltc-aniso: RGBA16F KTX 2.0); lobes = 2: <name>_t0 .. _t5, lutbake_ltc_aniso_specular_two_lobes, lobes = 3:
// <name>_t0 .. _t8, lutbake_ltc_aniso_specular_three_lobes (at the end). Tables (lutbake.ltc.aniso.texture_layout;
// benchmarks/bench_ltc_aniso.py writes ltc_aniso_textures.npy): three RGBA
// 3D textures, linear filtering, clamp to edge, of width N_PHI (x = view azimuth phi from the tangent, [0, pi/2]),
// height N_THETA (y = theta_v / (0.9999 pi / 2)) and depth N_A * N_B (z = layer b + N_B a: the 4th axis packed, as
// the paper's Tex3D path; a = alpha_x, b = alpha_y, both i / (N - 1), endpoint texels):
//   t0 = (M00, M01, M02, M10), t1 = (M11, M12, M20, M21), t2 = (M22, magnitude, fresnel, fit_error),
// M the LTC's matrix (clamped cosine -> lobe) in the tangent frame (T, B, N), |M e_z| = 1. The hardware
// interpolates phi, theta and b (within one a block of layers); a is interpolated here between two fetches:
// M is quadrilinear in (a, b, theta, phi), as the paper's. Views in the other three azimuth quadrants reflect M
// (diag(-1, 1, 1), diag(-1, -1, 1), diag(1, -1, 1)); the polygon integral's orientation follows sign(det M).
#ifndef LUTBAKE_LTC_ANISO_SIZE
#define LUTBAKE_LTC_ANISO_SIZE vec4(8.0)  // (N_A, N_B, N_THETA, N_PHI)
#endif

const float LUTBAKE_HALF_PI = 1.5707963267948966;

// (t0, t1, t2) at table coordinates u = (a, b, theta, phi) in [0, 1]^4, interpolated.
void lutbake_ltc_aniso_fetch(sampler3D t0, sampler3D t1, sampler3D t2, vec4 u, out vec4 c0, out vec4 c1,
                             out vec4 c2) {
    vec4 n = LUTBAKE_LTC_ANISO_SIZE;
    vec4 s = clamp(u, 0.0, 1.0) * (n - 1.0);
    float a0 = min(floor(s.x), n.x - 2.0);
    float w = s.x - a0;
    float depth = n.x * n.y;
    vec2 xy = (s.wz + 0.5) / n.wz;
    vec3 p0 = vec3(xy, (s.y + n.y * a0 + 0.5) / depth);
    vec3 p1 = vec3(xy, (s.y + n.y * (a0 + 1.0) + 0.5) / depth);
    c0 = mix(texture(t0, p0), texture(t0, p1), w);
    c1 = mix(texture(t1, p0), texture(t1, p1), w);
    c2 = mix(texture(t2, p0), texture(t2, p1), w);
}

// Specular radiance of a quad light (vertices p relative to the shading point, world space) of radiance Li on
// anisotropic GGX (alpha_x along the tangent T, alpha_y along B = N x T), Schlick Fresnel with f0:
// Li * I * (f0 magnitude + (1 - f0) fresnel), I the LTC's integral over the polygon.
vec3 lutbake_ltc_aniso_specular(sampler3D t0, sampler3D t1, sampler3D t2, vec3 N, vec3 T, vec3 V, float alpha_x,
                                float alpha_y, vec3 f0, vec3 p[4], vec3 Li, bool two_sided) {
    T = normalize(T - N * dot(N, T));
    vec3 B = cross(N, T);
    vec3 wo = vec3(dot(V, T), dot(V, B), dot(V, N));
    float theta = acos(clamp(wo.z, 0.0, 1.0));
    float phi = atan(wo.y, wo.x);
    // fold phi into [0, pi/2]: the reflection F with M(phi) = F M(folded)
    vec3 F = vec3(sign(wo.x) < 0.0 ? -1.0 : 1.0, sign(wo.y) < 0.0 ? -1.0 : 1.0, 1.0);
    float folded = atan(abs(wo.y), abs(wo.x));
    vec4 c0, c1, c2;
    vec4 u = vec4(alpha_x, alpha_y, theta / (0.9999 * LUTBAKE_HALF_PI), folded / LUTBAKE_HALF_PI);
    lutbake_ltc_aniso_fetch(t0, t1, t2, u, c0, c1, c2);
    mat3 M = transpose(mat3(c0.xyz, vec3(c0.w, c1.xy), vec3(c1.zw, c2.x)));  // rows -> GLSL columns
    M = mat3(F.x, 0.0, 0.0, 0.0, F.y, 0.0, 0.0, 0.0, 1.0) * M;
    mat3 Minv = inverse(M) * transpose(mat3(T, B, N));
    // one-sided: max(sign(det M) sum, 0); with det M < 0 that is |sum| - max(sum, 0)
    float I = (two_sided || determinant(M) > 0.0) ? lutbake_ltc_polygon(Minv, p, two_sided)
                                                   : lutbake_ltc_polygon(Minv, p, true) - lutbake_ltc_polygon(Minv, p, false);
    return Li * I * (f0 * c2.y + (1.0 - f0) * c2.z);
}

// Two lobes (kind ltc_aniso, lobes = 2: files <name>_t0 .. _t5): value = w_1 I(M_1) + w_2 I(M_2), (t0, t1, t2) lobe
// 1's and (t3, t4, t5) lobe 2's, each set laid out as a one-lobe table with t2.y = w_k and t2.z = w_k fresnel /
// magnitude (lutbake.ltc.aniso_lobes), so the specular is the one-lobe function on each set, added. Two fetches per
// texture and two polygon integrals per light.
vec3 lutbake_ltc_aniso_specular_two_lobes(sampler3D t0, sampler3D t1, sampler3D t2, sampler3D t3, sampler3D t4,
                                          sampler3D t5, vec3 N, vec3 T, vec3 V, float alpha_x, float alpha_y,
                                          vec3 f0, vec3 p[4], vec3 Li, bool two_sided) {
    return lutbake_ltc_aniso_specular(t0, t1, t2, N, T, V, alpha_x, alpha_y, f0, p, Li, two_sided) +
           lutbake_ltc_aniso_specular(t3, t4, t5, N, T, V, alpha_x, alpha_y, f0, p, Li, two_sided);
}

// Three lobes (lobes = 3: files <name>_t0 .. _t8): the two-lobe function's sum with (t6, t7, t8) lobe 3's set added.
vec3 lutbake_ltc_aniso_specular_three_lobes(sampler3D t0, sampler3D t1, sampler3D t2, sampler3D t3, sampler3D t4,
                                            sampler3D t5, sampler3D t6, sampler3D t7, sampler3D t8, vec3 N, vec3 T,
                                            vec3 V, float alpha_x, float alpha_y, vec3 f0, vec3 p[4], vec3 Li,
                                            bool two_sided) {
    return lutbake_ltc_aniso_specular_two_lobes(t0, t1, t2, t3, t4, t5, N, T, V, alpha_x, alpha_y, f0, p, Li,
                                                two_sided) +
           lutbake_ltc_aniso_specular(t6, t7, t8, N, T, V, alpha_x, alpha_y, f0, p, Li, two_sided);
}
