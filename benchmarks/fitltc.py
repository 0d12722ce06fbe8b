"""selfshadow/ltc_code's C++ fitter (fit/fitLTC.cpp: GGX, 64^2, one thread) built with g++ and timed, for bench_ltc.py.

LTC_CODE_DIR and GLM_DIR name source checkouts of selfshadow/ltc_code and g-truc/glm (ltc_code's submodule pins glm
40398d6; GLM_DIR defaults to LTC_CODE_DIR/external/glm). fitLTC.cpp and dds.cpp are compiled unchanged; -D_PLOT_ skips
plot.h (CImg, used only by the commented-out make_spherical_plots). The run writes results/ltc.js etc. in a temporary
directory; its g_ltc_1 (the inverse matrices) and g_ltc_2 (magnitude, Fresnel, sphere) are compared with the checkout's
published fit/results/ltc.js. Without the checkouts, the last measurement (fitltc_measured.json) is returned.
"""

from __future__ import annotations

import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CXX = os.environ.get("CXX", "g++")
FLAGS = ["-O2", "-std=c++11", "-DNDEBUG", "-D_PLOT_"]
MEASURED = Path(__file__).with_name("fitltc_measured.json")
NOT_BUILT = "not built: set LTC_CODE_DIR and GLM_DIR to checkouts of selfshadow/ltc_code and g-truc/glm"


def js_tables(path: Path) -> list[np.ndarray]:
    """g_ltc_1 and g_ltc_2 of an ltc.js, flat."""
    num = re.compile(r"-?[0-9.]+(?:e[-+]?[0-9]+)?")
    return [np.array(num.findall(s.split("[", 1)[1]), float) for s in path.read_text().split("var g_ltc_2")]


def time_fitltc(ltc_code_dir: str | None = None, glm_dir: str | None = None) -> dict:
    ltc = Path(ltc_code_dir or os.environ.get("LTC_CODE_DIR") or "/nonexistent")
    glm = Path(glm_dir or os.environ.get("GLM_DIR") or ltc / "external" / "glm")
    if not (ltc / "fit" / "fitLTC.cpp").is_file() or not (glm / "glm" / "glm.hpp").is_file():
        out = {"not_built": NOT_BUILT}
        if MEASURED.is_file():
            out["last_measured"] = json.loads(MEASURED.read_text())
        return out
    compiler = subprocess.run([CXX, "--version"], capture_output=True, text=True, check=True).stdout.splitlines()[0]
    with tempfile.TemporaryDirectory() as tmp:
        exe = Path(tmp) / "fitLTC"
        src = [str(ltc / "fit" / f) for f in ("fitLTC.cpp", "dds.cpp")]
        subprocess.run([CXX, *FLAGS, f"-I{glm}", "-o", str(exe), *src], check=True)
        (Path(tmp) / "results").mkdir()
        cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
        t0 = time.perf_counter()
        subprocess.run([str(exe)], cwd=tmp, stdout=subprocess.DEVNULL, check=True)
        seconds = time.perf_counter() - t0
        cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - cpu0
        ours, pub = js_tables(Path(tmp) / "results" / "ltc.js"), js_tables(ltc / "fit" / "results" / "ltc.js")
    return {
        "seconds": round(seconds, 1),
        "cpu_seconds": round(cpu, 1),
        "threads": 1,
        "compiler": compiler,
        "flags": " ".join(FLAGS),
        "matches_published_max_abs": float(np.abs(ours[0] - pub[0]).max()),
        "matches_published_median_abs": float(np.median(np.abs(ours[0] - pub[0]))),
        "matches_published_max_abs_ltc_2": float(np.abs(ours[1] - pub[1]).max()),
        "compared": "results/ltc.js vs published: g_ltc_1 (inverse matrices over their middle element), g_ltc_2",
    }


if __name__ == "__main__":
    res = time_fitltc(*sys.argv[1:3])
    print(json.dumps(res, indent=1))
