// A small C API over OpenSubdiv (Far and Bfr) for the benchmarks in scripts/: built by
// scripts/_osd.py with `g++ -O2 -shared -fPIC osd_capi.cpp -losdCPU`, loaded with ctypes, so that
// OpenSubdiv runs in the same process as ccproof (rounds interleaved, the same thread, the same load).
//
// Mesh input (every array owned by the caller, read during create only):
//   nv, X (nv x 3 doubles), nf, sizes (nf), idx (sum of sizes), creases (nc pairs, float weights),
//   corners (nk vertices, float weights), holes (nh faces), boundary (Sdc VtxBoundaryInterpolation),
//   flags (1: Chaikin creasing, 2: smooth triangle subdivision, 4: Loop scheme instead of Catmull-Clark).
// Points: ptex face, (s, t) in [0, 1]^2 (Far::PtexIndices order, as ccproof's `face`); Loop: the triangle,
//   (s, t) with s + t <= 1.
// Output: P, Ps, Pt (n x 3 doubles each), derivatives with respect to the ptex face's (s, t).
//
//   far_create(...)  adaptive refinement to `level`, PatchTable with Gregory end caps (double), PatchMap
//   bfr_create(..., approx)  Bfr::RefinerSurfaceFactory (approx > 0: approximation levels smooth = sharp =
//                    approx; else Bfr's defaults); one prepared Surface per base face (built at create)
//   *_eval(h, n, face, s, t, P, Ps, Pt)   one thread, in order; returns the number of points not found
//   far_patch_types(h, n, face, s, t, types)  Far::PatchDescriptor::Type of the patch holding each point
//                    (-1: none): 5 LOOP and 6 REGULAR are exact, 9 GREGORY_BASIS and 10 GREGORY_TRIANGLE end caps
//   *_free(h)
#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <cstdint>
#include <vector>

using namespace OpenSubdiv;

namespace {

struct V3 {
    double p[3];
    void Clear(void * = 0) { p[0] = p[1] = p[2] = 0; }
    void AddWithWeight(V3 const &s, double w) {
        p[0] += w * s.p[0];
        p[1] += w * s.p[1];
        p[2] += w * s.p[2];
    }
};

Far::TopologyRefiner *make_refiner(int nv, int nf, const int *sizes, const int *idx, int nc, const int *cre,
                                   const float *cw, int nk, const int *cor, const float *kw, int nh,
                                   const int *holes, int boundary, int flags) {
    Sdc::Options so;
    so.SetVtxBoundaryInterpolation((Sdc::Options::VtxBoundaryInterpolation)boundary);
    so.SetCreasingMethod(flags & 1 ? Sdc::Options::CREASE_CHAIKIN : Sdc::Options::CREASE_UNIFORM);
    so.SetTriangleSubdivision(flags & 2 ? Sdc::Options::TRI_SUB_SMOOTH : Sdc::Options::TRI_SUB_CATMARK);
    Far::TopologyDescriptor d;
    d.numVertices = nv;
    d.numFaces = nf;
    d.numVertsPerFace = sizes;
    d.vertIndicesPerFace = idx;
    d.numCreases = nc;
    d.creaseVertexIndexPairs = cre;
    d.creaseWeights = cw;
    d.numCorners = nk;
    d.cornerVertexIndices = cor;
    d.cornerWeights = kw;
    d.numHoles = nh;
    d.holeIndices = holes;
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    return Factory::Create(d, Factory::Options(flags & 4 ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK, so));
}

struct FarHandle {
    Far::TopologyRefiner *ref = nullptr;
    Far::PatchTable *tab = nullptr;
    Far::PatchMap *pmap = nullptr;
    std::vector<V3> V;
    ~FarHandle() {
        delete pmap;
        delete tab;
        delete ref;
    }
};

struct BfrHandle {
    Far::TopologyRefiner *ref = nullptr;
    std::vector<Bfr::Surface<double>> surf;   // per base face
    std::vector<std::vector<double>> pts;     // patch points per base face (3 doubles each)
    std::vector<int> ptex_face, ptex_sub;     // per ptex face: base face, sub-face (-1: the whole quad)
    ~BfrHandle() { delete ref; }
};

}  // namespace

extern "C" {

void *far_create(int nv, const double *X, int nf, const int *sizes, const int *idx, int nc, const int *cre,
                 const float *cw, int nk, const int *cor, const float *kw, int nh, const int *holes, int boundary,
                 int flags, int level) {
    FarHandle *h = new FarHandle;
    h->ref = make_refiner(nv, nf, sizes, idx, nc, cre, cw, nk, cor, kw, nh, holes, boundary, flags);
    if (!h->ref) {
        delete h;
        return nullptr;
    }
    Far::PatchTableFactory::Options po(level);
    po.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    po.SetPatchPrecision<double>();
    po.useInfSharpPatch = true;
    po.generateLegacySharpCornerPatches = false;
    h->ref->RefineAdaptive(po.GetRefineAdaptiveOptions());
    h->tab = Far::PatchTableFactory::Create(*h->ref, po);
    int nref = h->ref->GetNumVerticesTotal(), nloc = h->tab->GetNumLocalPoints();
    h->V.resize(nref + nloc);
    for (int i = 0; i < nv; ++i)
        for (int c = 0; c < 3; ++c) h->V[i].p[c] = X[3 * i + c];
    Far::PrimvarRefinerReal<double> pr(*h->ref);
    V3 *src = h->V.data();
    for (int l = 1; l <= h->ref->GetMaxLevel(); ++l) {
        V3 *dst = src + h->ref->GetLevel(l - 1).GetNumVertices();
        pr.Interpolate(l, src, dst);
        src = dst;
    }
    if (nloc) h->tab->GetLocalPointStencilTable<double>()->UpdateValues(h->V.data(), h->V.data() + nref);
    h->pmap = new Far::PatchMap(*h->tab);
    return h;
}

int64_t far_eval(void *hv, int64_t n, const int32_t *pf, const double *ps, const double *pt, double *P, double *Ps,
                 double *Pt) {
    FarHandle *h = (FarHandle *)hv;
    double w[20], ws[20], wt[20];
    int64_t missing = 0;
    for (int64_t i = 0; i < n; ++i) {
        double *o = P + 3 * i, *os = Ps + 3 * i, *ot = Pt + 3 * i;
        o[0] = o[1] = o[2] = os[0] = os[1] = os[2] = ot[0] = ot[1] = ot[2] = 0.0;
        Far::PatchTable::PatchHandle const *ph = h->pmap->FindPatch(pf[i], ps[i], pt[i]);
        if (!ph) {
            ++missing;
            continue;
        }
        h->tab->EvaluateBasis(*ph, ps[i], pt[i], w, ws, wt);
        if (h->tab->GetPatchParam(*ph).NonQuadRoot()) {  // EvaluateBasis scales by the depth of the
            for (int j = 0; j < 20; ++j) {               // n-gon's level-1 quad: back to the ptex face
                ws[j] *= 0.5;
                wt[j] *= 0.5;
            }
        }
        Far::ConstIndexArray cv = h->tab->GetPatchVertices(*ph);
        for (int j = 0; j < cv.size(); ++j) {
            double const *p = h->V[cv[j]].p;
            for (int c = 0; c < 3; ++c) {
                o[c] += w[j] * p[c];
                os[c] += ws[j] * p[c];
                ot[c] += wt[j] * p[c];
            }
        }
    }
    return missing;
}

void far_patch_types(void *hv, int64_t n, const int32_t *pf, const double *ps, const double *pt, int32_t *types) {
    FarHandle *h = (FarHandle *)hv;
    for (int64_t i = 0; i < n; ++i) {
        Far::PatchTable::PatchHandle const *ph = h->pmap->FindPatch(pf[i], ps[i], pt[i]);
        types[i] = ph ? (int32_t)h->tab->GetPatchDescriptor(*ph).GetType() : -1;
    }
}

void far_free(void *h) { delete (FarHandle *)h; }

void *bfr_create(int nv, const double *X, int nf, const int *sizes, const int *idx, int nc, const int *cre,
                 const float *cw, int nk, const int *cor, const float *kw, int nh, const int *holes, int boundary,
                 int flags, int approx) {
    BfrHandle *h = new BfrHandle;
    h->ref = make_refiner(nv, nf, sizes, idx, nc, cre, cw, nk, cor, kw, nh, holes, boundary, flags);
    if (!h->ref) {
        delete h;
        return nullptr;
    }
    Bfr::SurfaceFactory::Options fo;  // approx <= 0: Bfr's default approximation levels (smooth 2, sharp 6)
    if (approx > 0) fo.SetApproxLevelSmooth(approx).SetApproxLevelSharp(approx);
    Bfr::RefinerSurfaceFactory<> factory(*h->ref, fo);
    h->surf.resize(nf);
    h->pts.resize(nf);
    for (int f = 0; f < nf; ++f) {
        int ns = sizes[f] == 4 ? 1 : sizes[f];
        for (int k = 0; k < ns; ++k) {
            h->ptex_face.push_back(f);
            h->ptex_sub.push_back(sizes[f] == 4 ? -1 : k);
        }
        if (!factory.InitVertexSurface(f, &h->surf[f])) continue;  // a hole: no surface
        h->pts[f].resize(3 * h->surf[f].GetNumPatchPoints());
        h->surf[f].PreparePatchPoints(X, 3, h->pts[f].data(), 3);
    }
    return h;
}

int64_t bfr_eval(void *hv, int64_t n, const int32_t *pf, const double *ps, const double *pt, double *P, double *Ps,
                 double *Pt) {
    BfrHandle *h = (BfrHandle *)hv;
    int64_t missing = 0;
    for (int64_t i = 0; i < n; ++i) {
        double *o = P + 3 * i, *os = Ps + 3 * i, *ot = Pt + 3 * i;
        int f = h->ptex_face[pf[i]], k = h->ptex_sub[pf[i]];
        Bfr::Surface<double> const &S = h->surf[f];
        if (!S.IsValid()) {
            ++missing;
            for (int c = 0; c < 3; ++c) o[c] = os[c] = ot[c] = 0.0;
            continue;
        }
        double st[2] = {ps[i], pt[i]}, uv[2];
        double scale = 1.0;
        if (k < 0) {
            uv[0] = st[0];
            uv[1] = st[1];
        } else {  // the n-gon's sub-face k, normalized: the ptex face; its (s, t) spans half a unit of (u, v)
            Bfr::Parameterization param = S.GetParameterization();
            param.ConvertNormalizedSubFaceToCoord(k, st, uv);
            double z[2] = {0.0, 0.0}, one[2] = {1.0, 0.0}, a[2], b[2];
            param.ConvertNormalizedSubFaceToCoord(k, z, a);
            param.ConvertNormalizedSubFaceToCoord(k, one, b);
            scale = b[0] - a[0];
        }
        S.Evaluate(uv, h->pts[f].data(), 3, o, os, ot);
        for (int c = 0; c < 3; ++c) {
            os[c] *= scale;
            ot[c] *= scale;
        }
    }
    return missing;
}

void bfr_free(void *h) { delete (BfrHandle *)h; }

}  // extern "C"
