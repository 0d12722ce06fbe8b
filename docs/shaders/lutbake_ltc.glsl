// lutbake LTC area lights (Heitz, Dupuy, Hill & Neubelt 2016, "Real-Time Polygonal-Light Shading with Linearly
// Transformed Cosines"; edge integral fit from Hill & Heitz 2017, "Real-Time Area Lighting: a Journey from
// Research to Production"). Tables: lutbake kind `ltc` (presets ltc-ggx, ltc-threejs, ltc-eevee), ltc_code layout:
//   ltc_1 = (M^-1_00, M^-1_20, M^-1_02, M^-1_22) / M^-1_11, ltc_2 = (magnitude, fresnel, -, sphere),
//   N x N, endpoint texels, x = roughness (perceptual for GGX), y = sqrt(1 - NoV).
// GLSL 3.30. Define LUTBAKE_LTC_SIZE before including to use another table size.
#ifndef LUTBAKE_LTC_SIZE
#define LUTBAKE_LTC_SIZE 64.0
#endif

// Texture coordinate of (roughness, NoV): endpoint texels, i / (N - 1) at texel centres.
vec2 lutbake_ltc_uv(float roughness, float NoV) {
    return vec2(roughness, sqrt(1.0 - clamp(NoV, 0.0, 1.0))) * ((LUTBAKE_LTC_SIZE - 1.0) / LUTBAKE_LTC_SIZE)
        + 0.5 / LUTBAKE_LTC_SIZE;
}

// M^-1 from an ltc_1 texel (columns).
mat3 lutbake_ltc_minv(vec4 t1) {
    return mat3(vec3(t1.x, 0.0, t1.y), vec3(0.0, 1.0, 0.0), vec3(t1.z, 0.0, t1.w));
}

// Vector form factor of the edge (v1, v2) of unit vectors: acos(v1.v2) / (2 pi sin) * (v1 x v2), with
// Hill & Heitz's rational fit of theta / (2 pi sin theta).
vec3 lutbake_ltc_edge(vec3 v1, vec3 v2) {
    float x = dot(v1, v2);
    float y = abs(x);
    float a = 0.8543985 + (0.4965155 + 0.0145206 * y) * y;
    float b = 3.4175940 + (4.1616724 + y) * y;
    float v = a / b;
    float theta_sintheta = (x > 0.0) ? v : 0.5 * inversesqrt(max(1.0 - x * x, 1e-7)) - v;
    return cross(v1, v2) * theta_sintheta;
}

float lutbake_ltc_polygon(mat3 Minv, vec3 p[4], bool two_sided);

// Integral of the LTC over a quad light (vertices relative to the shading point, world space), normal N,
// view V: the polygon is expressed in (T1, T2, N), T1 = normalize(V - N NoV), transformed by M^-1, clipped to the
// horizon (Sutherland-Hodgman, up to 5 vertices), projected to the sphere and integrated edge by edge.
float lutbake_ltc_quad(vec3 N, vec3 V, mat3 Minv, vec3 p[4], bool two_sided) {
    vec3 T1 = normalize(V - N * dot(V, N));
    vec3 T2 = cross(N, T1);
    return lutbake_ltc_polygon(Minv * transpose(mat3(T1, T2, N)), p, two_sided);
}

// The same integral for Minv already composed with the shading frame (world -> LTC space); the sum is positive for
// vertices counter-clockwise seen from the shading point when det(Minv) > 0.
float lutbake_ltc_polygon(mat3 Minv, vec3 p[4], bool two_sided) {
    vec3 L[4];
    for (int i = 0; i < 4; ++i) L[i] = Minv * p[i];
    vec3 C[5];
    int n = 0;
    for (int i = 0; i < 4; ++i) {
        vec3 a = L[i];
        vec3 b = L[(i + 1) % 4];
        if (a.z >= 0.0) C[n++] = a;
        if ((a.z >= 0.0) != (b.z >= 0.0)) {
            vec3 q = mix(a, b, a.z / (a.z - b.z));
            q.z = 0.0;
            C[n++] = q;
        }
    }
    if (n < 3) return 0.0;
    float sum = 0.0;
    for (int i = 0; i < n; ++i) sum += lutbake_ltc_edge(normalize(C[i]), normalize(C[(i + 1) % n])).z;
    return two_sided ? abs(sum) : max(sum, 0.0);
}

// Specular radiance of a quad light of radiance Li (Schlick Fresnel with f0): Li * I * (f0 t2.x + (1 - f0) t2.y).
vec3 lutbake_ltc_specular(sampler2D ltc_1, sampler2D ltc_2, vec3 N, vec3 V, float roughness, vec3 f0, vec3 p[4],
                          vec3 Li, bool two_sided) {
    vec2 uv = lutbake_ltc_uv(roughness, dot(N, V));
    vec4 t1 = texture(ltc_1, uv);
    vec4 t2 = texture(ltc_2, uv);
    float I = lutbake_ltc_quad(N, V, lutbake_ltc_minv(t1), p, two_sided);
    return Li * I * (f0 * t2.x + (1.0 - f0) * t2.y);
}
