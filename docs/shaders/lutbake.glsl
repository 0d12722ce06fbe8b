// lutbake: sampling baked tables in GLSL (ES 3.0 / GL 3.3 and later).
// Contract: upload the rows as stored (row 0 first), so texture coordinate t = 0 is row 0; sample with
// LINEAR filtering and CLAMP_TO_EDGE. The exact formula for each axis of a file is in its metadata
// (lutbake:axes -> uv_formula); the functions below are those formulas for the shipped presets.
// The GL consumer test (tests/test_gl_consumer.py) compiles this file and checks every function.

// ---- one axis -------------------------------------------------------------------------------
// texel = "center", mapping "linear", range [0, 1]: value x sits at coordinate x.
float lutbake_u_center(float x) { return x; }
// texel = "endpoint": the value at index i is t = i / (N - 1), stored at texel centre (i + 0.5) / N.
float lutbake_u_endpoint(float t, float N) { return t * ((N - 1.0) / N) + 0.5 / N; }
// row_order = "hi_first": row 0 holds t near 1 (a vertical flip).
float lutbake_u_hi_first(float u) { return 1.0 - u; }

// ---- presets: uv for (NoV, perceptual roughness) --------------------------------------------
// lutbake default dfg, preset gltf (lut_ggx), preset unreal (PreIntegratedGF): columns NoV, rows r.
vec2 lutbake_dfg_uv(float NoV, float roughness) { return vec2(NoV, roughness); }
// preset blender-eevee: columns = roughness (endpoints), rows = sqrt(1 - NoV) (endpoints), N = 64.
vec2 lutbake_eevee_uv(float NoV, float roughness, float N) {
    return vec2(lutbake_u_endpoint(roughness, N), lutbake_u_endpoint(sqrt(max(1.0 - NoV, 0.0)), N));
}
// preset filament-corrected (image order, row 0 = roughest): rows at texel centres.
vec2 lutbake_filament_corrected_uv(float NoV, float roughness) { return vec2(NoV, 1.0 - roughness); }
// preset filament (as cmgen ships it, image order): row y holds r = (H - y + 0.5) / H, one texel
// rougher than its centre; this is the coordinate that reads the right value back from such a table.
vec2 lutbake_filament_shipped_uv(float NoV, float roughness, float H) {
    return vec2(NoV, 1.0 - (roughness - 1.0 / H));
}

// preset unity-hdrp (PreIntegratedFGD): x = sqrt(NoV), y = perceptual roughness, both endpoints, N = 64
// (HDRP's Remap01ToHalfTexelCoord(float2(sqrt(NdotV), perceptualRoughness), 64)).
vec2 lutbake_hdrp_uv(float NoV, float roughness, float N) {
    return vec2(lutbake_u_endpoint(sqrt(max(NoV, 0.0)), N), lutbake_u_endpoint(roughness, N));
}
// preset threejs (DFGLUTData.js): columns = roughness, rows = NoV, texel centres: texture2D(dfgLUT, vec2(roughness, dotNV)).
vec2 lutbake_threejs_uv(float NoV, float roughness) { return vec2(roughness, NoV); }
// preset bevy: as lutbake_dfg_uv (columns NoV, rows r, texel centres); preset godot (rows roughest first):
// as lutbake_filament_corrected_uv, vec2(NoV, 1.0 - r), which is Godot's own runtime lookup.

// ---- reconstruction ---------------------------------------------------------------------------
// layout scale_bias (R = scale, G = bias): E = f0 * scale + f90 * bias (f90 = 1 in the Schlick split sum).
vec3 lutbake_split_sum(vec2 t, vec3 f0) { return f0 * t.x + t.y; }
vec3 lutbake_split_sum_f90(vec2 t, vec3 f0, vec3 f90) { return f0 * t.x + f90 * t.y; }
// layout multiscatter (R = integral Fc f, G = integral f): E = mix(R, G, f0); Filament's energy compensation.
vec3 lutbake_multiscatter_E(vec2 t, vec3 f0) { return mix(vec3(t.x), vec3(t.y), f0); }
vec3 lutbake_energy_compensation(vec2 t, vec3 f0) { return 1.0 + f0 * (1.0 / t.y - 1.0); }
// layout multiscatter_disney (Unity HDRP): B = Disney diffuse FGD - 0.5.
float lutbake_hdrp_diffuse_fgd(vec3 t) { return t.z + 0.5; }
// layout scale_bias_f82 (Blender EEVEE): F82-tint metals, B = integral f/F (v.h)(1 - v.h)^6 (n.l).
vec3 lutbake_eevee_f82(vec3 t, vec3 f0, vec3 f90, vec3 f82_tint) {
    const float x = 6.0 / 7.0;
    vec3 b = mix(f0, vec3(1.0), pow(x, 5.0)) * (7.0 / pow(x, 6.0)) * (1.0 - f82_tint);
    return f0 * t.x + f90 * t.y - b * t.z;
}
