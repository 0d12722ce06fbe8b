"""The shipped shader snippets (docs/shaders/): HLSL compiles (glslangValidator's HLSL front end, when
installed) and defines the same functions as the GLSL file, which the GL consumer test compiles and runs."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

SHADERS = Path(__file__).resolve().parents[1] / "docs" / "shaders"
FUNC = re.compile(r"^\s*(?:float[234]?|vec[234])\s+(lutbake_\w+)\s*\(", re.M)

HLSL_MAIN = """
Texture2D<float4> DFG : register(t0);
SamplerState LinearClamp : register(s0);
float4 main(float4 pos : SV_Position, float3 p : TEXCOORD0) : SV_Target {
    float4 t = DFG.SampleLevel(LinearClamp, lutbake_eevee_uv(p.x, p.y, 64.0), 0);
    float3 a = lutbake_split_sum(t.xy, p) + lutbake_multiscatter_E(t.xy, p) * lutbake_energy_compensation(t.xy, p);
    a += lutbake_eevee_f82(t.xyz, p, 1.0.xxx, 0.5.xxx) + lutbake_split_sum_f90(t.xy, p, 1.0.xxx);
    float2 uv = lutbake_dfg_uv(p.x, p.y) + lutbake_filament_corrected_uv(p.x, p.y)
              + lutbake_filament_shipped_uv(p.x, p.y, 128.0);
    return float4(a, uv.x + uv.y + lutbake_u_center(p.z) + lutbake_u_hi_first(p.z) + lutbake_u_endpoint(p.z, 8.0));
}
"""


def test_glsl_and_hlsl_snippets_define_the_same_functions():
    glsl = set(FUNC.findall((SHADERS / "lutbake.glsl").read_text()))
    hlsl = set(FUNC.findall((SHADERS / "lutbake.hlsl").read_text()))
    assert glsl and glsl == hlsl
    assert all(f in HLSL_MAIN for f in hlsl)


def test_hlsl_snippet_compiles(tmp_path):
    tool = shutil.which("glslangValidator")
    if tool is None:
        pytest.skip("glslangValidator is not installed (Debian: apt-get install glslang-tools); HLSL not compiled")
    src = tmp_path / "t.hlsl"
    src.write_text((SHADERS / "lutbake.hlsl").read_text() + HLSL_MAIN)
    r = subprocess.run(
        [tool, "-D", "-V", "-S", "frag", "-e", "main", "-o", str(tmp_path / "t.spv"), str(src)],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stdout + r.stderr
