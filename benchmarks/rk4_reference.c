/* Hand-written C reference for benchmarks/bench_foundation.py: classical RK4 of N torque-free rigid
 * bodies, state y = [q_w, q_x, q_y, q_z, w1, w2, w3] (principal axes, rad/s) in structure-of-arrays
 * form (y[i*n + b]), all four stages, the update and q <- q/|q| fused in registers per body, bodies in
 * parallel (OpenMP) and SIMD lanes (the compiler's vectoriser). Euler coefficients
 * c = (c1, c2, c3) with c1 = (I2 - I3)/I1 and cyclic: one set for all bodies (stride 0) or one per body.
 * Built by the benchmark with  gcc -O3 -march=native -fopenmp -fno-math-errno -shared -fPIC
 * (-fno-math-errno: without it sqrt may set errno, and gcc keeps the loop scalar). */
#include <math.h>
#include <stddef.h>

#define RATES(qw, qx, qy, qz, w1, w2, w3, d)                                  \
    d[0] = 0.5 * (-qx * w1 - qy * w2 - qz * w3);                              \
    d[1] = 0.5 * (qw * w1 + qy * w3 - qz * w2);                               \
    d[2] = 0.5 * (qw * w2 - qx * w3 + qz * w1);                               \
    d[3] = 0.5 * (qw * w3 + qx * w2 - qy * w1);                               \
    d[4] = c1 * w2 * w3;                                                      \
    d[5] = c2 * w3 * w1;                                                      \
    d[6] = c3 * w1 * w2;

#define AXPY(a, k) qw + (a) * k[0], qx + (a) * k[1], qy + (a) * k[2], qz + (a) * k[3], \
                   w1 + (a) * k[4], w2 + (a) * k[5], w3 + (a) * k[6]

static inline __attribute__((always_inline)) void rates(double c1, double c2, double c3, double qw, double qx, double qy, double qz,
                         double w1, double w2, double w3, double *d)
{
    RATES(qw, qx, qy, qz, w1, w2, w3, d)
}

static inline __attribute__((always_inline)) void step(double *restrict y, ptrdiff_t n, ptrdiff_t b, double c1, double c2, double c3, double h)
{
    double qw = y[b], qx = y[n + b], qy = y[2 * n + b], qz = y[3 * n + b];
    double w1 = y[4 * n + b], w2 = y[5 * n + b], w3 = y[6 * n + b];
    double k1[7], k2[7], k3[7], k4[7];
    rates(c1, c2, c3, qw, qx, qy, qz, w1, w2, w3, k1);
    rates(c1, c2, c3, AXPY(0.5 * h, k1), k2);
    rates(c1, c2, c3, AXPY(0.5 * h, k2), k3);
    rates(c1, c2, c3, AXPY(h, k3), k4);
    const double a = h / 6.0;
    qw += a * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]);
    qx += a * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]);
    qy += a * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]);
    qz += a * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3]);
    w1 += a * (k1[4] + 2.0 * k2[4] + 2.0 * k3[4] + k4[4]);
    w2 += a * (k1[5] + 2.0 * k2[5] + 2.0 * k3[5] + k4[5]);
    w3 += a * (k1[6] + 2.0 * k2[6] + 2.0 * k3[6] + k4[6]);
    const double s = 1.0 / sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
    y[b] = qw * s; y[n + b] = qx * s; y[2 * n + b] = qy * s; y[3 * n + b] = qz * s;
    y[4 * n + b] = w1; y[5 * n + b] = w2; y[6 * n + b] = w3;
}

/* y (7, n) structure of arrays, advanced in place by `steps` steps of h; c (3,) shared by all bodies,
 * or (3, n) one column per body when per_body is non-zero. */
void rk4_batch(double *restrict y, const double *restrict c, int per_body, ptrdiff_t n, double h, long steps)
{
    const ptrdiff_t block = 64;
#pragma omp parallel for schedule(static)
    for (ptrdiff_t b0 = 0; b0 < n; b0 += block) {
        ptrdiff_t b1 = b0 + block < n ? b0 + block : n;
        for (long s = 0; s < steps; ++s) {
            if (per_body) {
#pragma omp simd
                for (ptrdiff_t b = b0; b < b1; ++b) step(y, n, b, c[b], c[n + b], c[2 * n + b], h);
            } else {
                const double c1 = c[0], c2 = c[1], c3 = c[2];
#pragma omp simd
                for (ptrdiff_t b = b0; b < b1; ++b) step(y, n, b, c1, c2, c3, h);
            }
        }
    }
}
