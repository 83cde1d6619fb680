/* The evaluation kernel of the patch table in C99 (built by setup.py as the optional extension ``ccproof.evaluate._clib``, loaded with ctypes by ccproof/evaluate/_ckernel.py).
 *
 * The same arithmetic as the numba kernel (ccproof/evaluate/_numba_kernel.py, evaluate_points) and the
 * numpy path, point by point: the same sums in the same order, compiled without floating-point
 * contraction (-ffp-contract=off: no FMA) and without reassociation, so that every backend gives the
 * same bits. What differs is the layout of the work: the bicubic sums run over the 12 contiguous
 * doubles (4 control points x 3 coordinates) of one net row at a time, which the compiler vectorizes
 * (each lane its own sum, in the same order), and the per-dimension variants (derivatives 0, 1, 2)
 * are compiled separately.
 *
 * Points are taken in blocks of CCP_BLOCK: the first pass finds their virtual faces (one loop: the
 * table reads of different points overlap), then their patches, parameters and scales and the basis
 * functions at the parameters (the divisions by 6 overlap the table reads), and prefetches their nets;
 * the second evaluates them. Corner nets of layers beyond the precomputed one are
 * kept in a cache the caller owns (one per thread, kept between calls on the same table). ccp_evaluate_at
 * takes the points in an order the caller gives (their faces' order: ccp_face_order), each read from and
 * written to its own row. A net computed from its job's ring is a product of a (16 + 1)-row operator with
 * the ring, taken four rows at a time in vectors (sums16), each lane its own sum in the scalar order.
 *
 * Threads: the kernel holds no global state; concurrent calls on disjoint blocks of points (ctypes
 * releases the GIL), each with its own cache, are safe, and their results do not depend on the blocks
 * or the caches (a net is the same sums whether computed or found in the cache).
 */
#ifdef CCP_PYTHON_MODULE /* built by setup.py: also an (empty) importable module, as tools that walk packages expect */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#endif
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define CCP_REGULAR 0
#define CCP_CORNER 1
#define CCP_SPLIT 2
/* corner nets kept per call (a power of 2; 408 bytes each) and the smallest call that uses the cache */
#ifndef CCP_CACHE_SLOTS
#define CCP_CACHE_SLOTS 16384
#endif
#define CCP_CACHE_MIN 256
#define CCP_HASH 2654435761u
#define CCP_NET 51 /* 17 x 3 doubles: 16 net rows relative to row 16, the origin */
#define CCP_LAYER_NETS 4 /* most layers of corner nets kept precomputed */
#define CCP_COMPOSED 2   /* layers of a corner face with composed operators (_table.COMPOSED_LAYERS) */

#if defined(__GNUC__)
#define CCP_INLINE static inline __attribute__((always_inline))
#define CCP_PREFETCH(p) __builtin_prefetch(p)
#define CCP_PREFETCH_W(p) __builtin_prefetch(p, 1)
#else
#define CCP_INLINE static inline
#define CCP_PREFETCH(p) ((void)(p))
#define CCP_PREFETCH_W(p) ((void)(p))
#endif

#if defined(__GNUC__) && defined(__x86_64__) && defined(__linux__) && !defined(CCP_NO_CLONES)
/* one binary for every x86-64 machine: the loader picks the widest variant the CPU runs */
#define CCP_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define CCP_CLONES
#endif

/* The patch table (ccproof.evaluate.patch_table.PatchTable), as pointers into its numpy arrays. The five
 * per-face offset arrays are int32 or int64 (``wide``); the rings are int32; every other integer array is
 * int64, except ``kind`` (int8) and the bools (one byte). Field order and types: _ckernel.py, _Table. */
typedef struct {
    const void *top, *job_root, *job_net, *job_corner, *job_ring;
    int64_t wide[5];
    const uint8_t *refused;
    const int8_t *kind;
    const int64_t *child;
    const double *u0, *v0, *h;
    const int64_t *leaf, *cfg;
    const uint8_t *cu, *cv;
    const int64_t *vop_start, *vn; /* per leaf: its operator in vop, its template's ring size N */
    const double *vop;
    const double *points; /* the positions the rings index (V x 3) */
    const int32_t *rings;
    int64_t split_depth;
    int64_t n_ptex;
    int64_t max_layers; /* max(1, max n_layers): the cache key's stride */
    int64_t n_corner;   /* corner faces of all jobs (the regular nets' cache keys follow theirs) */
    int64_t n_nets;     /* rows of ``nets`` (0: the regular nets are computed from the rings) */
    const double *nets, *ops;
    const int64_t *op_start, *op_size, *n_layers;
    const double *unit;
    const double *hot;
    int64_t n_hot; /* rows of ``hot`` (0: none) */
    const int64_t *cor_ring; /* NULL, or per corner face the row of its kept ring in ``ring`` (-1: none) */
    const double *ring;
    /* the nets of layers 0 .. n_layer_nets - 1 of every corner face, per layer 3 n_corner x 17 x 3 (layer 0:
     * ``hot``; the others filled by ccp_nets when the binding makes the table) */
    const double *layer_nets[CCP_LAYER_NETS];
    int64_t n_layer_nets;
    /* NULL, or per ptex face its 4 x 4 cells (row (v) major): job << grid_shift | the virtual face that holds
     * the cell (ccp_grid), uint32 or (grid_wide) int64 */
    const void *grid;
    int64_t grid_wide, grid_shift;
    /* NULL, or 1 / h per virtual face and 1 / (the patch side of ``unit``) per configuration and code (3 per
     * configuration), where every side is a power of two (the binding checks): then dividing by a side is
     * multiplying by its reciprocal, bit for bit (both the exact quotient, rounded once) */
    const double *inv_h, *inv_unit;
} ccp_table;

CCP_INLINE int64_t ld(const void *a, int64_t wide, int64_t i) {
    return wide ? ((const int64_t *)a)[i] : (int64_t)((const int32_t *)a)[i];
}

/* Cubic B-spline basis at x and its first and second derivatives (bspline_basis's formulas, the same
 * operations in the same order as the numba kernel's _basis). */
CCP_INLINE void basis(double x, double *b) {
    double t = 1.0 - x, x2 = x * x, x3 = x2 * x;
    b[0] = t * t * t / 6;
    b[1] = (3 * x3 - 6 * x2 + 4) / 6;
    b[2] = (-3 * x3 + 3 * x2 + 3 * x + 1) / 6;
    b[3] = x3 / 6;
    b[4] = -0.5 * t * t;
    b[5] = 1.5 * x2 - 2 * x;
    b[6] = -1.5 * x2 + x + 0.5;
    b[7] = 0.5 * x2;
    b[8] = t;
    b[9] = 3 * x - 2;
    b[10] = -3 * x + 1;
    b[11] = x;
}

#if defined(__GNUC__) && !defined(CCP_SCALAR) /* CCP_SCALAR: the portable code below (to check it) */
/* Four doubles, the lanes of one SIMD register (AVX2; two SSE2 registers or half an AVX-512 one): each
 * lane its own IEEE operations, the same as the scalar code's. */
typedef double v4d __attribute__((vector_size(32), aligned(8)));

CCP_INLINE v4d ld4(const double *p) {
    v4d r;
    memcpy(&r, p, sizeof r);
    return r;
}

CCP_INLINE v4d splat(double x) { return (v4d){x, x, x, x}; }

#if defined(__clang__)
#define CCP_SHUF(a, b, i, j, k, l) __builtin_shufflevector(a, b, i, j, k, l)
#else
#define CCP_SHUF(a, b, i, j, k, l) __builtin_shuffle(a, b, (v4di){i, j, k, l})
typedef int64_t v4di __attribute__((vector_size(32)));
#endif

/* The columns sum_j b_j net[i + 4 j, c] of the 4 x 4 x 3 net, as (i, c) lanes: three vectors of 4 lanes,
 * lanes 3 i + c, each summed over j = 0..3 from 0.0 in order; returned rearranged as X[i] = the three
 * coordinates of column i (lane 3 unused). */
CCP_INLINE void columns(const double *net, const double *b, v4d *X) {
    v4d b0 = splat(b[0]), b1 = splat(b[1]), b2 = splat(b[2]), b3 = splat(b[3]), z = splat(0.0), T[3];
    for (int m = 0; m < 3; m++)
        T[m] = (((z + b0 * ld4(net + 4 * m)) + b1 * ld4(net + 12 + 4 * m)) + b2 * ld4(net + 24 + 4 * m)) +
               b3 * ld4(net + 36 + 4 * m);
    X[0] = T[0];
    X[1] = CCP_SHUF(T[0], T[1], 3, 4, 5, 6);
    X[2] = CCP_SHUF(T[1], T[2], 2, 3, 4, 5);
    X[3] = CCP_SHUF(T[2], T[2], 1, 2, 3, 3);
}

/* sum_i a_i X[i] from 0.0, left to right, for the three coordinates at once */
CCP_INLINE v4d sum4v(const double *a, const v4d *X) {
    return (((splat(0.0) + splat(a[0]) * X[0]) + splat(a[1]) * X[1]) + splat(a[2]) * X[2]) + splat(a[3]) * X[3];
}

/* The three coordinates of x at dst; with ``more`` (row dst is not the output's last) all four lanes, one
 * store: the fourth lands on the next row's first coordinate, which the next point writes after this one. */
CCP_INLINE void put3(double *dst, v4d x, int more) {
    if (more)
        memcpy(dst, &x, sizeof x);
    else
        memcpy(dst, &x, 3 * sizeof(double));
}

/* basis(x) with its four divisions by 6 as one vector division (the same IEEE operations lane by lane) */
CCP_INLINE void basisv(double x, double *b) {
    double t = 1.0 - x, x2 = x * x, x3 = x2 * x;
    v4d n = {t * t * t, 3 * x3 - 6 * x2 + 4, -3 * x3 + 3 * x2 + 3 * x + 1, x3};
    v4d q = n / splat(6.0);
    memcpy(b, &q, sizeof q);
    b[4] = -0.5 * t * t;
    b[5] = 1.5 * x2 - 2 * x;
    b[6] = -1.5 * x2 + x + 0.5;
    b[7] = 0.5 * x2;
    b[8] = t;
    b[9] = 3 * x - 2;
    b[10] = -3 * x + 1;
    b[11] = x;
}

/* Row k of P and of the derivatives up to order D from the net (17 x 3) at (s, t), given the basis functions
 * bs = basis(s) and bt = basis(t), derivatives scaled by g per order (D a compile-time constant in each
 * caller): the columns T_r[i] = sum_j B_r(t)_j net[i + 4 j], then sum_i B(s)_i T_r[i], each sum from 0.0
 * left to right (the numba kernel's order). */
CCP_INLINE void bicubic(const double *net, const double *bs, const double *bt, double g, const int D, int64_t k,
                        int more, double *P, double *Pu, double *Pv, double *Puu, double *Puv, double *Pvv) {
    v4d T0[4], T1[4], T2[4];
    columns(net, bt, T0);
    put3(P + 3 * k, (v4d){net[48], net[49], net[50], 0.0} + sum4v(bs, T0), more);
    if (D >= 1) {
        v4d gg = splat(g);
        columns(net, bt + 4, T1);
        put3(Pu + 3 * k, sum4v(bs + 4, T0) * gg, more);
        put3(Pv + 3 * k, sum4v(bs, T1) * gg, more);
    }
    if (D >= 2) {
        v4d g2 = splat(g * g);
        columns(net, bt + 8, T2);
        put3(Puu + 3 * k, sum4v(bs + 8, T0) * g2, more);
        put3(Puv + 3 * k, sum4v(bs + 4, T1) * g2, more);
        put3(Pvv + 3 * k, sum4v(bs, T2) * g2, more);
    }
}
#else
/* sum_j a_j w_j from 0.0, left to right */
CCP_INLINE double sum4(const double *a, double w0, double w1, double w2, double w3) {
    return (((0.0 + a[0] * w0) + a[1] * w1) + a[2] * w2) + a[3] * w3;
}

/* The columns T[3 i + c] = sum_j b_j net[i + 4 j, c] (12 lanes, each summed over j in order). */
CCP_INLINE void columns(const double *net, const double *b, double *T) {
    for (int k = 0; k < 12; k++)
        T[k] = (((0.0 + b[0] * net[k]) + b[1] * net[12 + k]) + b[2] * net[24 + k]) + b[3] * net[36 + k];
}

/* Row k of P and of the derivatives up to order D (see the vector version above). */
CCP_INLINE void bicubic(const double *net, const double *bs, const double *bt, double g, const int D, int64_t k,
                        int more, double *P, double *Pu, double *Pv, double *Puu, double *Puv, double *Pvv) {
    double T0[12], T1[12], T2[12];
    (void)more;
    columns(net, bt, T0);
    for (int c = 0; c < 3; c++)
        P[3 * k + c] = net[48 + c] + sum4(bs, T0[c], T0[3 + c], T0[6 + c], T0[9 + c]);
    if (D >= 1) {
        columns(net, bt + 4, T1);
        for (int c = 0; c < 3; c++) {
            Pu[3 * k + c] = sum4(bs + 4, T0[c], T0[3 + c], T0[6 + c], T0[9 + c]) * g;
            Pv[3 * k + c] = sum4(bs, T1[c], T1[3 + c], T1[6 + c], T1[9 + c]) * g;
        }
    }
    if (D >= 2) {
        double g2 = g * g;
        columns(net, bt + 8, T2);
        for (int c = 0; c < 3; c++) {
            Puu[3 * k + c] = sum4(bs + 8, T0[c], T0[3 + c], T0[6 + c], T0[9 + c]) * g2;
            Puv[3 * k + c] = sum4(bs + 4, T1[c], T1[3 + c], T1[6 + c], T1[9 + c]) * g2;
            Pvv[3 * k + c] = sum4(bs, T2[c], T2[3 + c], T2[6 + c], T2[9 + c]) * g2;
        }
    }
}
#endif

/* The ring of ``job``: N indices into points */
CCP_INLINE const int32_t *ring_of(const ccp_table *T, int64_t job) {
    return T->rings + ld(T->job_ring, T->wide[4], job);
}

/* The difference of ring point j and the origin x0: X[rg[j]] - x0 (rg given), else row j - 1 of rel (n x 3, the
 * ring relative to its vertex already). */
CCP_INLINE void rel_point(const double *pts, const int32_t *rg, const double *x0, const double *rel, int64_t j,
                          double *r) {
    if (rg != NULL) {
        const double *x = pts + 3 * (int64_t)rg[j];
        r[0] = x[0] - x0[0];
        r[1] = x[1] - x0[1];
        r[2] = x[2] - x0[2];
    } else {
        r[0] = rel[3 * (j - 1)];
        r[1] = rel[3 * (j - 1) + 1];
        r[2] = rel[3 * (j - 1) + 2];
    }
}

/* W[3 i + c] (i < 16) = the sum over j = 1, 2, ..., n - 1 in order, from 0.0, of M[stride j + i] r_j[c] (r_j:
 * rel_point); with o, also e[c] = the same sum of o[ostride j] r_j[c]. */
#if defined(__GNUC__) && !defined(CCP_SCALAR)
CCP_INLINE void sums16(const double *pts, const int32_t *rg, const double *x0, const double *rel, int64_t n,
                       const double *M, int64_t stride, const double *o, int64_t ostride, double *W, double *e) {
    v4d a[12]; /* a[4 c + q]: lanes i = 4 q .. 4 q + 3 of coordinate c, each lane its own sum */
    double e0 = 0.0, e1 = 0.0, e2 = 0.0, r[3];
    for (int k = 0; k < 12; k++) a[k] = splat(0.0);
    for (int64_t j = 1; j < n; j++) {
        rel_point(pts, rg, x0, rel, j, r);
        v4d R0 = splat(r[0]), R1 = splat(r[1]), R2 = splat(r[2]);
        const double *w = M + stride * j;
        for (int q = 0; q < 4; q++) {
            v4d wq = ld4(w + 4 * q);
            a[q] += wq * R0;
            a[4 + q] += wq * R1;
            a[8 + q] += wq * R2;
        }
        if (o != NULL) {
            double oj = o[ostride * j];
            e0 += oj * r[0];
            e1 += oj * r[1];
            e2 += oj * r[2];
        }
    }
    double t[48];
    memcpy(t, a, sizeof t);
    for (int i = 0; i < 16; i++) {
        W[3 * i] = t[i];
        W[3 * i + 1] = t[16 + i];
        W[3 * i + 2] = t[32 + i];
    }
    if (o != NULL) {
        e[0] = e0;
        e[1] = e1;
        e[2] = e2;
    }
}
#else
CCP_INLINE void sums16(const double *pts, const int32_t *rg, const double *x0, const double *rel, int64_t n,
                       const double *M, int64_t stride, const double *o, int64_t ostride, double *W, double *e) {
    double a0[16], a1[16], a2[16], e0 = 0.0, e1 = 0.0, e2 = 0.0, r[3];
    for (int i = 0; i < 16; i++) a0[i] = a1[i] = a2[i] = 0.0;
    for (int64_t j = 1; j < n; j++) {
        rel_point(pts, rg, x0, rel, j, r);
        const double *w = M + stride * j;
        for (int i = 0; i < 16; i++) {
            a0[i] += w[i] * r[0];
            a1[i] += w[i] * r[1];
            a2[i] += w[i] * r[2];
        }
        if (o != NULL) {
            e0 += o[ostride * j] * r[0];
            e1 += o[ostride * j] * r[1];
            e2 += o[ostride * j] * r[2];
        }
    }
    for (int i = 0; i < 16; i++) {
        W[3 * i] = a0[i];
        W[3 * i + 1] = a1[i];
        W[3 * i + 2] = a2[i];
    }
    if (o != NULL) {
        e[0] = e0;
        e[1] = e1;
        e[2] = e2;
    }
}
#endif

/* Net W (17 x 3) of the regular leaf vf of ``job``: row i the sum over the ring points j = 1, 2, ... in order,
 * from 0.0, of op[j, i] (X[ring[j]] - X[ring[0]]), row 16 that sum plus X[ring[0]] (op: vop, N x 17). */
CCP_CLONES static void regular_net(const ccp_table *T, int64_t job, int64_t vf, double *W) {
    const double *op = T->vop + T->vop_start[vf];
    const int32_t *rg = ring_of(T, job);
    const double *x0 = T->points + 3 * (int64_t)rg[0];
    double e[3];
    sums16(T->points, rg, x0, NULL, T->vn[vf], op, 17, op + 16, 17, W, e);
    W[48] = e[0] + x0[0];
    W[49] = e[1] + x0[1];
    W[50] = e[2] + x0[2];
}

/* Net W (17 x 3, row 16 the limit point: the sum over j = 1, 2, ... of o[j] (X[ring[j]] - X[ring[0]]) from 0.0,
 * plus X[ring[0]]; o the operator row after Q) of patch ``code`` of layer ``lay`` of the corner face ``vf`` of
 * ``job``. Layers below CCP_COMPOSED: the composed operator M (N x 16) of the layer and code, the sums over the
 * ring points j = 1, 2, ... in order from 0.0 of M[j, i] (X[ring[j]] - X[ring[0]]). Deeper: its ring relative
 * to the corner vertex first (rows 1 .. Nc - 1: Q @ (X[ring] - X[ring[0]]), the
 * sums over the ring points j = 1, 2, ... in order from 0.0; Q: vop, N x (Nc - 1)), then L[lay, code] @ that
 * ring summed over its points j = 1, 2, ... in order, from 0.0. */
CCP_CLONES static void corner_net(const ccp_table *T, int64_t job, int64_t vf, int64_t cfg, int64_t lay, int64_t code,
                                  int64_t ci, double *W) {
    int64_t Nc = T->op_size[cfg], N = T->vn[vf], m = Nc - 1;
    const double *op = T->ops + T->op_start[cfg] + (3 * lay + code) * 16 * Nc;
    const double *q = T->vop + T->vop_start[vf];
    const int32_t *rg = ring_of(T, job);
    const double *x0 = T->points + 3 * (int64_t)rg[0];
    const double *o = q + N * m; /* the limit point's weights */
    double e[3];
    if (lay < CCP_COMPOSED) { /* one product: the composed operator (N x 16) of this layer and code */
        sums16(T->points, rg, x0, NULL, N, o + N + (3 * lay + code) * N * 16, 16, o, 1, W, e);
        W[48] = e[0] + x0[0];
        W[49] = e[1] + x0[1];
        W[50] = e[2] + x0[2];
        return;
    }
    double e0 = 0.0, e1 = 0.0, e2 = 0.0;
    double rc_[3 * (m > 0 ? m : 1)], *rc = rc_;
    int64_t kept = T->cor_ring != NULL ? T->cor_ring[ci] : -1;
    if (kept >= 0) { /* the kept ring (the same sums); the limit point's sum alone */
        rc = (double *)(T->ring + 3 * kept);
        for (int64_t j = 1; j < N; j++) {
            const double *x = T->points + 3 * (int64_t)rg[j];
            e0 += o[j] * (x[0] - x0[0]);
            e1 += o[j] * (x[1] - x0[1]);
            e2 += o[j] * (x[2] - x0[2]);
        }
    }
    if (kept < 0) for (int64_t r = 0; r < 3 * m; r++) rc[r] = 0.0;
    for (int64_t j = 1; j < N && kept < 0; j++) {
        const double *x = T->points + 3 * (int64_t)rg[j];
        double r0 = x[0] - x0[0], r1 = x[1] - x0[1], r2 = x[2] - x0[2];
        const double *w = q + m * j;
        for (int64_t r = 0; r < m; r++) {
            rc[3 * r] += w[r] * r0;
            rc[3 * r + 1] += w[r] * r1;
            rc[3 * r + 2] += w[r] * r2;
        }
        e0 += o[j] * r0;
        e1 += o[j] * r1;
        e2 += o[j] * r2;
    }
    sums16(T->points, NULL, x0, rc, Nc, op, 16, NULL, 0, W, e);
    W[48] = e0 + x0[0];
    W[49] = e1 + x0[1];
    W[50] = e2 + x0[2];
}

/* The corner-net cache (the caller's buffer of CCP_CACHE_WORDS doubles, zero when new, kept between calls
 * on the same table by one thread at a time): word 0 the last block number, then CCP_CACHE_SLOTS slots of
 * CCP_SLOT words, each [key + 1 (0: empty), the block that last took it, 3 unused, the net (51)]: the tag
 * shares the net's first cache line. */
#define CCP_SLOT 56
#define CCP_CACHE_WORDS (8 + CCP_SLOT * CCP_CACHE_SLOTS)
/* locate's answer for a point whose net is a corner net beyond the precomputed layer */
static const double CCP_DEEP[1] = {0.0};

/* 2^k for -1022 <= k <= 1023 (an exact power of two: scaling by it is ldexp while the result is normal;
 * here k is a layer, at most a few hundred) */
CCP_INLINE double pow2(int64_t k) {
    uint64_t b = (uint64_t)(1023 + k) << 52;
    double x;
    memcpy(&x, &b, sizeof x);
    return x;
}

/* The exponent e of frexp(x) (x = m 2^e, 1/2 <= m < 1) for x > 0 */
CCP_INLINE int64_t expo(double x) {
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    int64_t f = (int64_t)((b >> 52) & 0x7ff);
    if (f == 0) { /* subnormal */
        int e;
        frexp(x, &e);
        return e;
    }
    return f - 1022;
}

/* A point whose net is a corner net of a layer beyond the precomputed one: what corner_net needs. */
typedef struct {
    int64_t job, vf, cfg, lay, code, ci;
} ccp_deep;

/* The net of a point that locate did not find stored: a regular net (cfg < 0) or a corner net. */
static void deep_net(const ccp_table *T, const ccp_deep *d, double *W) {
    if (d->cfg < 0)
        regular_net(T, d->job, d->vf, W);
    else
        corner_net(T, d->job, d->vf, d->cfg, d->lay, d->code, d->ci, W);
}

/* The net of point (pf, uu, ww), its parameter (s, t) in the patch and the scale g = 1 / h. Returns NULL
 * for a point evaluation refuses, and CCP_DEEP for a corner net of a layer beyond the precomputed one,
 * with what computes it in *dp (resolved by the caller: cache or scratch). */
/* The job and virtual face of point (pf, uu, ww); returns the face's kind, or -1 for a point evaluation
 * refuses. */
CCP_INLINE int find_face(const ccp_table *T, int64_t pf, double uu, double ww, int64_t *jb, int64_t *vfc) {
    if (pf < 0 || pf >= T->n_ptex || !(uu >= 0.0 && uu <= 1.0 && ww >= 0.0 && ww <= 1.0) || T->refused[pf])
        return -1;
    int64_t q, job, vf;
    int kind;
    if (T->grid != NULL) { /* the cell's job and virtual face in one read, then the splits finer than the cell */
        int64_t i = 16 * pf + 4 * ((ww >= 0.25) + (ww >= 0.5) + (ww >= 0.75)) + (uu >= 0.25) + (uu >= 0.5) + (uu >= 0.75);
        int64_t e = T->grid_wide ? ((const int64_t *)T->grid)[i] : (int64_t)((const uint32_t *)T->grid)[i];
        job = e >> T->grid_shift;
        vf = e & (((int64_t)1 << T->grid_shift) - 1);
        kind = T->kind[vf];
        for (int64_t it = 0; it < T->split_depth && kind == CCP_SPLIT; it++) {
            double half = T->h[vf] * 0.5;
            q = (uu >= T->u0[vf] + half) + 2 * (ww >= T->v0[vf] + half);
            vf = T->child[4 * vf + q];
            kind = T->kind[vf];
        }
        *jb = job;
        *vfc = vf;
        return kind;
    }
    q = (uu >= 0.5) + 2 * (ww >= 0.5);
    job = ld(T->top, T->wide[0], 4 * pf + q);
    vf = ld(T->job_root, T->wide[1], job);
    kind = T->kind[vf];
    if (T->split_depth > 0) { /* the first level without a branch on the kind (mixed points mispredict it) */
        double half = T->h[vf] * 0.5;
        q = (uu >= T->u0[vf] + half) + 2 * (ww >= T->v0[vf] + half);
        int64_t c = T->child[4 * vf + q], sp = -(int64_t)(kind == CCP_SPLIT); /* c = -1 unless split */
        vf ^= (vf ^ c) & sp;
        kind = T->kind[vf];
    }
    for (int64_t it = 1; it < T->split_depth && kind == CCP_SPLIT; it++) {
        double half = T->h[vf] * 0.5;
        q = (uu >= T->u0[vf] + half) + 2 * (ww >= T->v0[vf] + half);
        vf = T->child[4 * vf + q];
        kind = T->kind[vf];
    }
    *jb = job;
    *vfc = vf;
    return kind;
}

/* c ? a : b without a branch (the corner sides cu, cv of a face are 0 or 1 in no order: a branch on them
 * mispredicts): the bits of a or of b, both computed. */
CCP_INLINE double pick(int c, double a, double b) {
    uint64_t x, y, m = (uint64_t)0 - (uint64_t)(c != 0);
    memcpy(&x, &a, sizeof x);
    memcpy(&y, &b, sizeof y);
    x = (x & m) | (y & ~m);
    memcpy(&a, &x, sizeof a);
    return a;
}

/* The net of a point in virtual face vf (kind ``kind``) of ``job`` (find_face), its (s, t) and g. */
CCP_INLINE const double *locate(const ccp_table *T, int64_t job, int64_t vf, int kind, double uu, double ww,
                                ccp_deep *dp, double *s, double *t, double *g) {
    const double *net;
    double pu0, pv0, h, gi = 0.0;
    if (kind == CCP_CORNER) {
        double U0 = T->u0[vf], V0 = T->v0[vf], H = T->h[vf];
        int cu = T->cu[vf], cv = T->cv[vf];
        double du, dv;
        /* the distances to the irregular corner */
        double au = pick(cu, (U0 + H) - uu, uu - U0), av = pick(cv, (V0 + H) - ww, ww - V0);
        if (T->inv_h != NULL) {
            double r = T->inv_h[vf];
            du = au * r;
            dv = av * r;
        } else {
#if defined(__GNUC__) && !defined(CCP_SCALAR)
            v4d dd = (v4d){au, av, 1.0, 1.0} / splat(H);
            du = dd[0];
            dv = dd[1];
#else
            du = au / H;
            dv = av / H;
#endif
        }
        double mx = du >= dv ? du : dv;
        int64_t cfg = T->cfg[vf];
        int64_t nmax = T->n_layers[cfg] - 1, lay;
        if (mx > 0) {
            int64_t e = expo(mx);
            lay = -e;
            if (lay < 0) lay = 0;
            if (lay > nmax) lay = nmax;
        } else {
            lay = nmax;
        }
        double up = pow2(lay); /* exact scalings: ldexp(du, lay), ldexp(dv, lay), ldexp(H, -lay) */
        du = du * up;
        dv = dv * up;
        static const int64_t codes[4] = {1, 2, 0, 1}; /* (a, b): (0, 0) 1, (0, 1) 2, (1, 0) 0, (1, 1) 1 */
        int64_t code = codes[2 * (du >= 0.5) + (dv >= 0.5)];
        double sc = H * pow2(-lay);
        const double *un = T->unit + 9 * cfg + 3 * code;
        pu0 = un[0] * sc + pick(cu, U0 + H, U0);
        pv0 = un[1] * sc + pick(cv, V0 + H, V0);
        h = un[2] * sc;
        if (T->inv_h != NULL) gi = T->inv_unit[3 * cfg + code] * T->inv_h[vf] * up; /* 1 / h, exactly */
        int64_t ci = ld(T->job_corner, T->wide[3], job) + T->leaf[vf];
        if (lay < T->n_layer_nets) {
            net = T->layer_nets[lay] + CCP_NET * (3 * ci + code);
        } else {
            dp->job = job;
            dp->vf = vf;
            dp->cfg = cfg;
            dp->lay = lay;
            dp->code = code;
            dp->ci = ci;
            net = CCP_DEEP;
        }
    } else {
        int64_t p = ld(T->job_net, T->wide[2], job) + T->leaf[vf];
        if (T->n_nets > 0) {
            net = T->nets + CCP_NET * p;
        } else { /* computed from the ring (cfg -1: a regular net) */
            dp->job = job;
            dp->vf = vf;
            dp->cfg = -1;
            dp->lay = 0;
            dp->code = 0;
            dp->ci = p;
            net = CCP_DEEP;
        }
        pu0 = T->u0[vf];
        pv0 = T->v0[vf];
        h = T->h[vf];
        if (T->inv_h != NULL) gi = T->inv_h[vf];
    }
    if (T->inv_h != NULL) {
        double x = (uu - pu0) * gi, y = (ww - pv0) * gi;
        *g = gi;
        x = 0.0 > x ? 0.0 : x;
        y = 0.0 > y ? 0.0 : y;
        *s = 1.0 < x ? 1.0 : x;
        *t = 1.0 < y ? 1.0 : y;
        return net;
    }
#if defined(__GNUC__) && !defined(CCP_SCALAR)
    v4d qq = (v4d){uu - pu0, ww - pv0, 1.0, 1.0} / splat(h); /* three divisions in one */
    double x = qq[0], y = qq[1];
    *g = qq[2];
#else
    double x = (uu - pu0) / h, y = (ww - pv0) / h;
    *g = 1.0 / h;
#endif
    x = 0.0 > x ? 0.0 : x; /* min(max(x, 0.0), 1.0) with Python's max and min */
    y = 0.0 > y ? 0.0 : y;
    *s = 1.0 < x ? 1.0 : x;
    *t = 1.0 < y ? 1.0 : y;
    return net;
}

/* Prefetch the positions of the ring a deep net (locate's *dp) is computed from. */
CCP_INLINE void prefetch_ring(const ccp_table *T, const ccp_deep *d) {
    const int32_t *rg = ring_of(T, d->job);
    for (int64_t j = 0; j < T->vn[d->vf]; j++) CCP_PREFETCH(T->points + 3 * (int64_t)rg[j]);
}

/* Points per block: the first pass locates them (and prefetches their nets), the second evaluates them. */
#define CCP_BLOCK 32

#if defined(__GNUC__) && !defined(CCP_SCALAR)
#define BASIS basisv
#else
#define BASIS basis
#endif

/* ix NULL: point k is (f[k], u[k], v[k]), its results row k; else point k is row ix[k] of the inputs and of the
 * outputs (the rows of ix distinct: each output row written once, three coordinates at a time). */
CCP_INLINE int64_t run(const ccp_table *T, int64_t n, const int64_t *ix, const int64_t *f, const double *u,
                       const double *v, const int D, double *P, double *Pu, double *Pv, double *Puu, double *Puv,
                       double *Pvv, double *cache) {
    int64_t *base = n >= CCP_CACHE_MIN ? (int64_t *)cache : NULL;
    double S[CCP_BLOCK], Tt[CCP_BLOCK], G[CCP_BLOCK];
    double BS[CCP_BLOCK][12], BT[CCP_BLOCK][12]; /* the basis functions at the block's (s, t) */
    double W[CCP_BLOCK][CCP_NET]; /* the corner nets of a block without a cache */
    const double *N[CCP_BLOCK];
    ccp_deep dp[CCP_BLOCK];
    int64_t *slot[CCP_BLOCK];
    int64_t key[CCP_BLOCK];
    int64_t bad = -1, k = 0, block = base != NULL ? base[0] : 0;
    /* the rings of deep nets prefetched once their slots show them missing: where the table keeps the layer-0
     * corner nets, deep nets are those of the few corner faces' deeper layers, which the cache mostly holds; else
     * (every corner net deep, few found) with the slots, in pass 1 */
    const int late = base != NULL && T->n_layer_nets > 0;
    while (k < n && bad < 0) {
        int64_t k0 = k;
        int m = 0;
        /* pass 1: the virtual faces of the block's points (independent table reads, overlapped), then their
         * patches, prefetching the nets (or the cache slots of the deep corner nets) */
        int64_t JB[CCP_BLOCK], VF[CCP_BLOCK], AT[CCP_BLOCK];
        int KD[CCP_BLOCK];
        if (ix != NULL) /* the next block's input rows, read in its pass 1, and output rows, written in its pass 2 */
            for (int64_t j = k + CCP_BLOCK; j < n && j < k + 2 * CCP_BLOCK; j++) {
                int64_t r = ix[j];
                CCP_PREFETCH(f + r);
                CCP_PREFETCH(u + r);
                CCP_PREFETCH(v + r);
                CCP_PREFETCH_W(P + 3 * r);
                if (D >= 1) {
                    CCP_PREFETCH_W(Pu + 3 * r);
                    CCP_PREFETCH_W(Pv + 3 * r);
                }
                if (D >= 2) {
                    CCP_PREFETCH_W(Puu + 3 * r);
                    CCP_PREFETCH_W(Puv + 3 * r);
                    CCP_PREFETCH_W(Pvv + 3 * r);
                }
            }
        for (; k < n && m < CCP_BLOCK; k++, m++) {
            int64_t r = AT[m] = ix != NULL ? ix[k] : k;
            KD[m] = find_face(T, f[r], u[r], v[r], JB + m, VF + m);
            if (KD[m] < 0) {
                bad = k;
                break;
            }
        }
        int DL[CCP_BLOCK], nd = 0; /* the points with deep corner nets, in order */
        for (int i = 0; i < m; i++) {
            int64_t kk = AT[i];
            const double *net = locate(T, JB[i], VF[i], KD[i], u[kk], v[kk], dp + i, S + i, Tt + i, G + i);
            N[i] = net;
            BASIS(S[i], BS[i]);
            BASIS(Tt[i], BT[i]);
            DL[nd] = i;
            nd += net == CCP_DEEP;
            if (net == CCP_DEEP) {
                if (base == NULL || late == 0) prefetch_ring(T, dp + i); /* (computed in pass 2, or likely to be) */
                if (base == NULL) continue;
                key[i] = dp[i].cfg < 0 ? 3 * T->max_layers * T->n_corner + dp[i].ci
                                       : 3 * (T->max_layers * dp[i].ci + dp[i].lay) + dp[i].code;
                slot[i] = base + 8 + CCP_SLOT * (int64_t)(((uint64_t)key[i] * CCP_HASH) & (CCP_CACHE_SLOTS - 1));
                net = (const double *)slot[i];
            }
            for (int j = 0; j < CCP_NET; j += 8) CCP_PREFETCH(net + j);
            CCP_PREFETCH(net + CCP_NET + 4);
        }
        if (late) /* the rings of the deep nets not in the cache (their slots' tags, prefetched above) */
            for (int jd = 0; jd < nd; jd++)
                if (slot[DL[jd]][0] != key[DL[jd]] + 1) prefetch_ring(T, dp + DL[jd]);
        /* pass 2: the deep corner nets (found in the cache, or computed; only the points of DL, without a
         * branch per point on whether a net is deep), then the bicubics in order; a slot taken by an
         * earlier point of this block and wanted by another net: the points before are evaluated first */
        int i0 = 0;
        block++;
        for (int jd = 0; jd < nd; jd++) {
            int i = DL[jd];
            const ccp_deep *d = dp + i;
            if (base == NULL) {
                deep_net(T, d, W[i]);
                N[i] = W[i];
                continue;
            }
            int64_t *sl = slot[i];
            if (sl[0] != key[i] + 1) {
                if (sl[1] == block) {
                    for (; i0 < i; i0++) bicubic(N[i0], BS[i0], BT[i0], G[i0], D, AT[i0], ix == NULL && k0 + i0 + 1 < n, P, Pu, Pv, Puu, Puv, Pvv);
                    block++;
                }
                deep_net(T, d, (double *)(sl + 5));
                sl[0] = key[i] + 1;
            }
            sl[1] = block;
            N[i] = (const double *)(sl + 5);
        }
        for (; i0 < m; i0++) bicubic(N[i0], BS[i0], BT[i0], G[i0], D, AT[i0], ix == NULL && k0 + i0 + 1 < n, P, Pu, Pv, Puu, Puv, Pvv);
    }
    if (base != NULL) base[0] = block;
    return bad;
}

CCP_CLONES static int64_t run0(const ccp_table *T, int64_t n, const int64_t *ix, const int64_t *f, const double *u,
                               const double *v, double *P, double *cache) {
    return run(T, n, ix, f, u, v, 0, P, NULL, NULL, NULL, NULL, NULL, cache);
}

CCP_CLONES static int64_t run1(const ccp_table *T, int64_t n, const int64_t *ix, const int64_t *f, const double *u,
                               const double *v, double *P, double *Pu, double *Pv, double *cache) {
    return run(T, n, ix, f, u, v, 1, P, Pu, Pv, NULL, NULL, NULL, cache);
}

CCP_CLONES static int64_t run2(const ccp_table *T, int64_t n, const int64_t *ix, const int64_t *f, const double *u,
                               const double *v, double *P, double *Pu, double *Pv, double *Puu, double *Puv,
                               double *Pvv, double *cache) {
    return run(T, n, ix, f, u, v, 2, P, Pu, Pv, Puu, Puv, Pvv, cache);
}

/* Fill P (n x 3) and, for d >= 1, Pu, Pv, for d >= 2, Puu, Puv, Pvv (n x 3 each, C order) at the points
 * (f[k], u[k], v[k]). ``cache``: NULL, or ccp_cache_words() doubles, zero when new, used by one call at a
 * time and only with this table (it keeps the corner nets of layers beyond the precomputed one; the results
 * are the same bits with or without it). Returns -1, or the index of the first point whose face is out of
 * range or refused or whose (u, v) is outside [0, 1]^2 or NaN (the outputs from that point on are not
 * written). */
int64_t ccp_evaluate(const ccp_table *T, int64_t n, const int64_t *f, const double *u, const double *v, int64_t d,
                     double *P, double *Pu, double *Pv, double *Puu, double *Puv, double *Pvv, double *cache) {
    if (d <= 0) return run0(T, n, NULL, f, u, v, P, cache);
    if (d == 1) return run1(T, n, NULL, f, u, v, P, Pu, Pv, cache);
    return run2(T, n, NULL, f, u, v, P, Pu, Pv, Puu, Puv, Pvv, cache);
}

/* ccp_evaluate on the points ix[0], ix[1], ... ix[n - 1] (distinct rows of f, u, v and of the outputs, which
 * hold at least max(ix) + 1 rows), in that order: each point's results in its own row, the same bits as
 * ccp_evaluate gives it (the caller orders the points by face: the table read in order, the nets of a patch
 * found in the cache). Returns -1, or the position k (not the row ix[k]) of the first point refused; the
 * points from position k on are not written. */
int64_t ccp_evaluate_at(const ccp_table *T, int64_t n, const int64_t *ix, const int64_t *f, const double *u,
                        const double *v, int64_t d, double *P, double *Pu, double *Pv, double *Puu, double *Puv,
                        double *Pvv, double *cache) {
    if (d <= 0) return run0(T, n, ix, f, u, v, P, cache);
    if (d == 1) return run1(T, n, ix, f, u, v, P, Pu, Pv, cache);
    return run2(T, n, ix, f, u, v, P, Pu, Pv, Puu, Puv, Pvv, cache);
}

/* The size of a corner-net cache, in doubles. */
int64_t ccp_cache_words(void) { return CCP_CACHE_WORDS; }

#define CCP_STACK 256
/* The nets the binding keeps, by the sums the kernel computes at evaluation time, walking the tree of virtual
 * faces of each of the table's ``n_jobs`` jobs once. ``kind`` CCP_CORNER: layer ``lay`` of every corner face
 * (corner_net; W: 3 n_corner x 17 x 3 doubles, row 3 ci + code the net of patch ``code`` of corner face ci; rows
 * of corner faces with fewer layers are zero), for ``layer_nets``; ``kind`` CCP_REGULAR: every regular patch
 * (regular_net; W: n_regular x 17 x 3 doubles, row job_net + leaf; ``lay`` unused), for ``nets`` where the table
 * keeps none. Returns 0, -1 when a job's tree of virtual faces is deeper than the walk's stack, or -2 for
 * another ``kind``. */
int64_t ccp_nets(const ccp_table *T, int64_t n_jobs, int64_t kind, int64_t lay, double *W) {
    if (kind != CCP_REGULAR && kind != CCP_CORNER) return -2;
    for (int64_t job = 0; job < n_jobs; job++) {
        int64_t stack[CCP_STACK], ns = 0; /* 3 more per level: 44 levels of splits at most in a table */
        stack[ns++] = ld(T->job_root, T->wide[1], job);
        while (ns > 0) {
            int64_t vf = stack[--ns];
            if (T->kind[vf] == CCP_SPLIT) {
                if (ns + 4 > CCP_STACK) return -1;
                for (int q = 0; q < 4; q++) stack[ns++] = T->child[4 * vf + q];
            } else if (T->kind[vf] == kind && kind == CCP_REGULAR) {
                regular_net(T, job, vf, W + CCP_NET * (ld(T->job_net, T->wide[2], job) + T->leaf[vf]));
            } else if (T->kind[vf] == kind) {
                int64_t cfg = T->cfg[vf], ci = ld(T->job_corner, T->wide[3], job) + T->leaf[vf];
                for (int64_t code = 0; code < 3; code++) {
                    double *w = W + CCP_NET * (3 * ci + code);
                    if (lay < T->n_layers[cfg])
                        corner_net(T, job, vf, cfg, lay, code, ci, w);
                    else
                        memset(w, 0, CCP_NET * sizeof(double));
                }
            }
        }
    }
    return 0;
}

/* The points 0 .. n - 1 in the order of their keys min(max(f[k], 0), n_faces - 1) >> shift, stable (a counting sort:
 * points of one face together, faces in order), into order (n); counts: scratch of (n_faces - 1 >> shift) + 2 int64.
 * Returns 0. */
int64_t ccp_face_order(int64_t n, const int64_t *f, int64_t n_faces, int64_t shift, int64_t *counts, int64_t *order) {
    int64_t nb = ((n_faces - 1) >> shift) + 1, top = n_faces - 1;
    for (int64_t b = 0; b <= nb; b++) counts[b] = 0;
    for (int64_t k = 0; k < n; k++) {
        int64_t x = f[k] < 0 ? 0 : f[k] > top ? top : f[k];
        counts[(x >> shift) + 1]++;
    }
    for (int64_t b = 0; b < nb; b++) counts[b + 1] += counts[b];
    for (int64_t k = 0; k < n; k++) {
        int64_t x = f[k] < 0 ? 0 : f[k] > top ? top : f[k];
        order[counts[x >> shift]++] = k;
    }
    return 0;
}

/* The grid of ``grid`` (16 n_ptex entries, uint32 or, ``wide``, int64): per ptex face and cell (i, j) of its 4 x 4
 * cells (u in [i / 4, (i + 1) / 4), the last closed, v likewise, entry 16 face + 4 j + i), the job of the cell's
 * quadrant << ``shift`` | the smallest virtual face of that job that holds the whole cell (the kernel's comparisons
 * at the cell's centre; virtual faces are dyadic squares, so every point of the cell makes the same choices down to
 * it; a child that does not hold the whole cell is not taken). Refused faces get 0. Returns 0, -1 when a virtual
 * face's number does not fit ``shift`` bits or a job's the bits left (32 or 63 in all), or -2 when a job's face does
 * not hold a whole cell (no grid then). */
CCP_INLINE int holds(const ccp_table *T, int64_t vf, int64_t i, int64_t j) {
    return T->u0[vf] <= 0.25 * i && T->u0[vf] + T->h[vf] >= 0.25 * (i + 1) && T->v0[vf] <= 0.25 * j &&
           T->v0[vf] + T->h[vf] >= 0.25 * (j + 1);
}

int64_t ccp_grid(const ccp_table *T, void *grid, int64_t wide, int64_t shift) {
    int64_t bits = wide ? 63 : 32;
    if (shift < 0 || shift >= bits) return -1;
    for (int64_t pf = 0; pf < T->n_ptex; pf++)
        for (int64_t j = 0; j < 4; j++)
            for (int64_t i = 0; i < 4; i++) {
                int64_t e = 0, c = 16 * pf + 4 * j + i;
                if (!T->refused[pf]) {
                    double uu = (i + 0.5) / 4, ww = (j + 0.5) / 4;
                    int64_t job = ld(T->top, T->wide[0], 4 * pf + (uu >= 0.5) + 2 * (ww >= 0.5));
                    int64_t vf = ld(T->job_root, T->wide[1], job);
                    if (!holds(T, vf, i, j)) return -2;
                    for (int64_t it = 0; it < T->split_depth && T->kind[vf] == CCP_SPLIT; it++) {
                        double half = T->h[vf] * 0.5;
                        int64_t ch = T->child[4 * vf + (uu >= T->u0[vf] + half) + 2 * (ww >= T->v0[vf] + half)];
                        if (!holds(T, ch, i, j)) break;
                        vf = ch;
                    }
                    if (vf >> shift != 0 || job >> (bits - shift) != 0) return -1;
                    e = job << shift | vf;
                }
                if (wide)
                    ((int64_t *)grid)[c] = e;
                else
                    ((uint32_t *)grid)[c] = (uint32_t)e;
            }
    return 0;
}

/* The layout this file was compiled with: the binding refuses a library whose structure differs. */
int64_t ccp_abi(void) { return 1000 * (int64_t)sizeof(ccp_table) + 8; }

/* ------------------------------------------------------------------------------------------------------------
 * The ring walk of the table's setup (the numba kernel's _ring_walks, ccproof/evaluate/_numba_kernel.py, step
 * for step): the canonical depth-1 ring of quad g[k] of an all-quad complex from its corner r[k]. */

/* Step of the walk: list the face of half-edge c (read from c on) unless seen. Returns 0, or -1 when the
 * arrays are full (*n = -1; *nf = -1 when the faces are full, else one more). */
static int take_face(int64_t c, const int64_t *org, int64_t *pos, uint8_t *seen, int32_t *ring, int64_t maxn,
                     int64_t *faces, int64_t maxf, int64_t *fc, int64_t *fl, int64_t *n, int64_t *nf) {
    int64_t hf = c / 4;
    if (seen[hf]) return 0;
    if (*nf >= maxf) {
        *n = -1;
        *nf = -1;
        return -1;
    }
    seen[hf] = 1;
    fl[*nf] = hf;
    int64_t j0 = c - 4 * hf;
    for (int64_t t = 0; t < 4; t++) {
        int64_t hc = 4 * hf + (j0 + t) % 4;
        int64_t uu = org[hc];
        int64_t q = pos[uu];
        if (q < 0) {
            if (*n >= maxn) {
                faces[4 * *nf] = -1;
                *n = -1;
                *nf += 1;
                return -1;
            }
            q = *n;
            pos[uu] = *n;
            ring[*n] = (int32_t)uu;
            fc[*n] = hc;
            *n += 1;
        }
        faces[4 * *nf + t] = q;
    }
    *nf += 1;
    return 0;
}

/* For every k < nk: the ring of quad g[k] from corner r[k] (vertex labels rings[k, :nring[k]], rows of maxn),
 * its faces in ring labels (faces[k, :nfaces[k]], rows of maxf x 4) and a 64-bit FNV-1a hash of (nring,
 * faces); nring[k] = -1 when the ring does not fit the arrays or the walk does not close. pos (n_vertices)
 * and seen (n_faces) are scratch, -1 / 0 on entry and on return. Returns 0, or -1 when the scratch arrays
 * could not be allocated (nothing written). */
int64_t ccp_ring_walks(const int64_t *org, const int64_t *nxt, const int64_t *prv, const int64_t *twin, int64_t *pos,
                       uint8_t *seen, int64_t nk, const int64_t *g, const int64_t *r, int32_t *rings, int64_t maxn,
                       int64_t *nring, int64_t *faces, int64_t maxf, int64_t *nfaces, uint64_t *hashes) {
    int64_t *fc = (int64_t *)malloc(sizeof(int64_t) * (size_t)(maxn > 0 ? maxn : 1));
    int64_t *fl = (int64_t *)malloc(sizeof(int64_t) * (size_t)(maxf > 0 ? maxf : 1));
    if (fc == NULL || fl == NULL) {
        free(fc);
        free(fl);
        return -1;
    }
    for (int64_t k = 0; k < nk; k++) {
        int64_t gk = g[k];
        int32_t *ring = rings + maxn * k;
        int64_t *fk = faces + 4 * maxf * k;
        int64_t n = 0, nf = 1;
        int ok = 1;
        seen[gk] = 1;
        fl[0] = gk;
        for (int64_t i = 0; i < 4; i++) {
            int64_t h = 4 * gk + (r[k] + i) % 4;
            int64_t vv = org[h];
            fk[i] = i;
            if (pos[vv] >= 0) {
                ok = 0;
                break;
            }
            pos[vv] = n;
            ring[n] = (int32_t)vv;
            fc[n] = h;
            n++;
        }
        int64_t idx = 0;
        while (ok && idx < 4) {
            int64_t c0 = fc[idx];
            take_face(c0, org, pos, seen, ring, maxn, fk, maxf, fc, fl, &n, &nf);
            int64_t c = twin[prv[c0]];
            int64_t steps = 0;
            while (n >= 0 && c >= 0 && c != c0 && steps < 4096) { /* counter-clockwise */
                take_face(c, org, pos, seen, ring, maxn, fk, maxf, fc, fl, &n, &nf);
                c = twin[prv[c]];
                steps++;
            }
            if (n < 0 || steps >= 4096) {
                ok = 0;
                break;
            }
            if (c != c0) { /* an open fan: then clockwise from c0 */
                int64_t t_ = twin[c0];
                c = t_ < 0 ? -1 : nxt[t_];
                while (n >= 0 && c >= 0 && steps < 4096) {
                    take_face(c, org, pos, seen, ring, maxn, fk, maxf, fc, fl, &n, &nf);
                    t_ = twin[c];
                    c = t_ < 0 ? -1 : nxt[t_];
                    steps++;
                }
                if (n < 0 || steps >= 4096) {
                    ok = 0;
                    break;
                }
            }
            idx++;
        }
        if (nf < 0) nf = maxf;
        int64_t top = n < 0 ? maxn : n;
        for (int64_t i = 0; i < top; i++) /* reset the scratch arrays */
            if (i < maxn && ring[i] >= 0 && pos[ring[i]] == i) pos[ring[i]] = -1;
        for (int64_t i = 0; i < nf; i++) seen[fl[i]] = 0;
        nring[k] = ok ? n : -1;
        nfaces[k] = nf;
        uint64_t hsh = 14695981039346656037ull, prime = 1099511628211ull;
        hsh = (hsh ^ (uint64_t)(n > 0 ? n : 0)) * prime;
        for (int64_t i = 0; i < nf; i++)
            for (int64_t t = 0; t < 4; t++) hsh = (hsh ^ (uint64_t)(fk[4 * i + t] + 1)) * prime;
        hashes[k] = hsh;
    }
    free(fc);
    free(fl);
    return 0;
}

#ifdef CCP_PYTHON_MODULE
static struct PyModuleDef ccp_module = {PyModuleDef_HEAD_INIT, "_clib",
                                        "The C evaluation kernel: loaded with ctypes by ccproof.evaluate._ckernel "
                                        "(nothing to call from Python).",
                                        -1, NULL, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__clib(void) { return PyModule_Create(&ccp_module); }
#endif
