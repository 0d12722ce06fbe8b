/* The C baseline of benchmarks/bench.py: lutbake's sobol_vndf estimator of the split-sum DFG table
 * (GGX, height-correlated Smith, Schlick scale/bias), written plainly in C, float32 terms and float64
 * accumulation as in the Warp kernel. A measuring stick only: compiled at benchmark time with
 *   gcc -O3 -march=native -fopenmp dfg_vndf.c -lm
 * Usage: dfg_vndf IN OUT THREADS
 *   IN  = int32 n_texels, int32 n_points, float32 nov[n], float32 alpha[n], float32 pts[n_points][2]
 *   OUT = float64 out[n][2];   prints the kernel's wall seconds on stdout. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#define COS_EPS 1.0e-7f
#define INV_PI 0.31830988618379067f

static inline float lambda_ggx(float c, float a) {
    if (c <= COS_EPS) return 1.0e30f;
    float c2 = c * c;
    return 0.5f * (sqrtf(c2 + a * a * (1.0f - c2)) / c - 1.0f);
}

static inline float d_ggx(float hx, float hy, float hz, float a) {
    if (hz <= 0.0f) return 0.0f;
    float a2 = a * a, d = hz * hz * a2 + (hx * hx + hy * hy);
    return a2 * INV_PI / (d * d);
}

static void texel(float nov, float a, int np, const float *pts, double *out) {
    float vx = sqrtf(fmaxf(1.0f - nov * nov, 0.0f)), vz = nov;
    /* spherical-cap VNDF (Dupuy & Benyoub 2023) */
    float sx = a * vx, sz = vz, inv = 1.0f / sqrtf(sx * sx + sz * sz);
    float whx = sx * inv, whz = sz * inv;
    float lv = lambda_ggx(nov, a), g1v = 1.0f / (1.0f + lv);
    double acc0 = 0.0, acc1 = 0.0, w = 1.0 / np;
    for (int k = 0; k < np; ++k) {
        float phi = 6.2831853071795864f * pts[2 * k], z = (1.0f - pts[2 * k + 1]) * (1.0f + whz) - whz;
        float s = sqrtf(fminf(fmaxf(1.0f - z * z, 0.0f), 1.0f));
        float nx = s * cosf(phi) + whx, ny = s * sinf(phi), nz = z + whz;
        float hx = a * nx, hy = a * ny, hz = fmaxf(nz, 0.0f);
        float hn = 1.0f / sqrtf(hx * hx + hy * hy + hz * hz);
        hx *= hn; hy *= hn; hz *= hn;
        float voh = vx * hx + vz * hz;
        if (voh <= COS_EPS || nov <= COS_EPS) continue;
        float D = d_ggx(hx, hy, hz, a);
        float p = g1v * voh * D / nov;
        if (p <= 0.0f) continue;
        float nol = 2.0f * voh * hz - vz;
        if (nol <= COS_EPS) continue;
        float G2 = 1.0f / (1.0f + lv + lambda_ggx(nol, a));
        float g = D * G2 * voh / nov;
        float m = fminf(fmaxf(1.0f - voh, 0.0f), 1.0f), m2 = m * m, fc = m2 * m2 * m;
        acc0 += w * (double)((1.0f - fc) * g / p);
        acc1 += w * (double)(fc * g / p);
    }
    out[0] = acc0;
    out[1] = acc1;
}

int main(int argc, char **argv) {
    if (argc != 4) { fprintf(stderr, "usage: %s IN OUT THREADS\n", argv[0]); return 2; }
    FILE *f = fopen(argv[1], "rb");
    int n, np;
    if (!f || fread(&n, 4, 1, f) != 1 || fread(&np, 4, 1, f) != 1) return 1;
    float *nov = malloc(4 * n), *alpha = malloc(4 * n), *pts = malloc(8 * np);
    double *out = malloc(16 * (size_t)n);
    if (fread(nov, 4, n, f) != (size_t)n || fread(alpha, 4, n, f) != (size_t)n || fread(pts, 8, np, f) != (size_t)np)
        return 1;
    fclose(f);
    omp_set_num_threads(atoi(argv[3]));
    double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 64)
    for (int i = 0; i < n; ++i) texel(nov[i], alpha[i], np, pts, out + 2 * i);
    printf("%.6f\n", omp_get_wtime() - t0);
    f = fopen(argv[2], "wb");
    fwrite(out, 16, n, f);
    fclose(f);
    return 0;
}
