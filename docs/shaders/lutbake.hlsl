// lutbake: sampling baked tables in HLSL (SM 4.0 and later). Same contract as lutbake.glsl:
// file row 0 is texture row 0 (v = 0, the top row in D3D: no flip needed for DDS/KTX2 'rd');
// sample with a LINEAR / CLAMP sampler. Each file's axes metadata (uv_formula) gives the exact formula.
// tests/test_shaders.py compiles it with glslangValidator's HLSL front end (Debian glslang-tools) where installed.

float lutbake_u_center(float x) { return x; }
float lutbake_u_endpoint(float t, float N) { return t * ((N - 1.0) / N) + 0.5 / N; }
float lutbake_u_hi_first(float u) { return 1.0 - u; }

float2 lutbake_dfg_uv(float NoV, float roughness) { return float2(NoV, roughness); }
float2 lutbake_eevee_uv(float NoV, float roughness, float N) {
    return float2(lutbake_u_endpoint(roughness, N), lutbake_u_endpoint(sqrt(max(1.0 - NoV, 0.0)), N));
}
float2 lutbake_filament_corrected_uv(float NoV, float roughness) { return float2(NoV, 1.0 - roughness); }
float2 lutbake_filament_shipped_uv(float NoV, float roughness, float H) {
    return float2(NoV, 1.0 - (roughness - 1.0 / H));
}
float2 lutbake_hdrp_uv(float NoV, float roughness, float N) {
    return float2(lutbake_u_endpoint(sqrt(max(NoV, 0.0)), N), lutbake_u_endpoint(roughness, N));
}
float2 lutbake_threejs_uv(float NoV, float roughness) { return float2(roughness, NoV); }

float3 lutbake_split_sum(float2 t, float3 f0) { return f0 * t.x + t.y; }
float3 lutbake_split_sum_f90(float2 t, float3 f0, float3 f90) { return f0 * t.x + f90 * t.y; }
float3 lutbake_multiscatter_E(float2 t, float3 f0) { return lerp(t.xxx, t.yyy, f0); }
float3 lutbake_energy_compensation(float2 t, float3 f0) { return 1.0 + f0 * (1.0 / t.y - 1.0); }
float lutbake_hdrp_diffuse_fgd(float3 t) { return t.z + 0.5; }
float3 lutbake_eevee_f82(float3 t, float3 f0, float3 f90, float3 f82_tint) {
    const float x = 6.0 / 7.0;
    float3 b = lerp(f0, 1.0.xxx, pow(x, 5.0)) * (7.0 / pow(x, 6.0)) * (1.0 - f82_tint);
    return f0 * t.x + f90 * t.y - b * t.z;
}

// Example (UE4-style EnvBRDF with preset unreal, or lutbake's default dfg):
//   Texture2D<float2> DFG; SamplerState LinearClamp;
//   float2 t = DFG.SampleLevel(LinearClamp, lutbake_dfg_uv(NoV, roughness), 0);
//   float3 specular = prefiltered * lutbake_split_sum(t, f0);
