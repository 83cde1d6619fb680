/* The compute bound of scripts/bench_evaluate.py: P + Pu + Pv of ONE bicubic net (held in registers) at n
 * points, the evaluator's own formulas with every freedom the kernel does not take (-O3 -march=native
 * -ffast-math: contraction into FMA, reassociation, vectorization across points). No table, no gather:
 * what one core can do at best. Built and loaded by bench_evaluate.py (gcc), not part of the package. */
#include <stdint.h>

/* P, Pu, Pv at one point (x, y) of the bicubic net N (16 points x 3, rows of 12): the evaluator's own
 * formulas, shared by the three loops below. */
static inline void point(const double *N, double x, double y, double *P, double *Pu, double *Pv) {
    double w = 1.0 - x, x2 = x * x, x3 = x2 * x;
    double b0 = w * w * w / 6, b1 = (3 * x3 - 6 * x2 + 4) / 6, b2 = (-3 * x3 + 3 * x2 + 3 * x + 1) / 6,
           b3 = x3 / 6, d0 = -0.5 * w * w, d1 = 1.5 * x2 - 2 * x, d2 = -1.5 * x2 + x + 0.5, d3 = 0.5 * x2;
    double z = 1.0 - y, y2 = y * y, y3 = y2 * y;
    double c0 = z * z * z / 6, c1 = (3 * y3 - 6 * y2 + 4) / 6, c2 = (-3 * y3 + 3 * y2 + 3 * y + 1) / 6,
           c3 = y3 / 6, e0 = -0.5 * z * z, e1 = 1.5 * y2 - 2 * y, e2 = -1.5 * y2 + y + 0.5, e3 = 0.5 * y2;
    for (int c = 0; c < 3; c++) {
        double a[4], g[4];
        for (int j = 0; j < 4; j++) {
            const double *r = N + 12 * j + c;
            a[j] = b0 * r[0] + b1 * r[3] + b2 * r[6] + b3 * r[9];
            g[j] = d0 * r[0] + d1 * r[3] + d2 * r[6] + d3 * r[9];
        }
        P[c] = c0 * a[0] + c1 * a[1] + c2 * a[2] + c3 * a[3];
        Pu[c] = c0 * g[0] + c1 * g[1] + c2 * g[2] + c3 * g[3];
        Pv[c] = e0 * a[0] + e1 * a[1] + e2 * a[2] + e3 * a[3];
    }
}

void ideal(int64_t n, const double *s, const double *t, const double *net, double *P, double *Pu, double *Pv) {
    double N[48];
    for (int k = 0; k < 48; k++) N[k] = net[k];
    for (int64_t i = 0; i < n; i++) {
        point(N, s[i], t[i], P + 3 * i, Pu + 3 * i, Pv + 3 * i);
    }
}

/* The two-thread ceiling of scripts/bench_evaluate.py: the same ideal work with the evaluator's memory traffic,
 * per point the face id, u and v read and P, Pu, Pv written (the arrays of an evaluation), the net one of 16
 * (held in L1) chosen by the face id: what two threads can gain on ideal compiled work of this shape. */
void ideal_points(int64_t n, const int64_t *f, const double *s, const double *t, const double *nets, double *P,
                  double *Pu, double *Pv) {
    for (int64_t i = 0; i < n; i++) {
        const double *N = nets + 48 * (f[i] & 15);
        point(N, s[i], t[i], P + 3 * i, Pu + 3 * i, Pv + 3 * i);
    }
}

/* The latency bound of scripts/bench_scans.py: the same ideal work, but each point gathers the net of its own
 * face from a table of one 16-point net per face (48 doubles, 384 B: six cache lines), as a table that stores a
 * net per patch must: in the points' order, the face ids of the evaluation. Where the table outgrows the caches
 * this is bound by the latency of the memory system (how many of those misses it overlaps), not by arithmetic. */
void ideal_gather(int64_t n, const int64_t *f, const double *s, const double *t, const double *nets, double *P,
                  double *Pu, double *Pv) {
    for (int64_t i = 0; i < n; i++) {
        const double *N = nets + 48 * f[i];
        point(N, s[i], t[i], P + 3 * i, Pu + 3 * i, Pv + 3 * i);
    }
}

/* One dependent load after another through a random cycle (next[i] the index after i): the latency of one miss
 * when the cycle outgrows the caches. Returns the last index (so that the loop is not optimized away). */
int64_t chase(int64_t steps, const int64_t *next) {
    int64_t i = 0;
    for (int64_t k = 0; k < steps; k++) i = next[i];
    return i;
}
