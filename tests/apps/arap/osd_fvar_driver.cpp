// OpenSubdiv's own face-varying subdivision (Far::PrimvarRefiner, FVAR_LINEAR_CORNERS_ONLY, VTX_BOUNDARY_EDGE_ONLY)
// for tests/apps/arap/test_arap_control_fvar.py.  Build: g++ -std=c++14 osd_fvar_driver.cpp -o drv -losdCPU
// (Debian/Ubuntu: apt-get install libosd-dev g++).
// stdin: n_vertices n_faces n_values level, the face sizes, the vertex indices, the value indices, the values (u v).
// stdout: the level's n_values, its values (u v), its n_faces and every face's value indices.
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <cstdio>
#include <vector>
using namespace OpenSubdiv;
struct UV { double u, v; void Clear(void* = 0) { u = v = 0; } void AddWithWeight(UV const& s, float w) { u += w * s.u; v += w * s.v; } };
int main() {
    int nv, nf, nuv, level;
    if (scanf("%d %d %d %d", &nv, &nf, &nuv, &level) != 4) return 1;
    std::vector<int> sizes(nf), vi, ui;
    int tot = 0;
    for (int i = 0; i < nf; ++i) { if (scanf("%d", &sizes[i]) != 1) return 1; tot += sizes[i]; }
    vi.resize(tot); ui.resize(tot);
    for (int i = 0; i < tot; ++i) if (scanf("%d", &vi[i]) != 1) return 1;
    for (int i = 0; i < tot; ++i) if (scanf("%d", &ui[i]) != 1) return 1;
    std::vector<UV> uv(nuv);
    for (int i = 0; i < nuv; ++i) if (scanf("%lf %lf", &uv[i].u, &uv[i].v) != 2) return 1;
    typedef Far::TopologyDescriptor Descriptor;
    Sdc::Options opt;
    opt.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    opt.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_CORNERS_ONLY);
    Descriptor desc;
    desc.numVertices = nv; desc.numFaces = nf;
    desc.numVertsPerFace = sizes.data(); desc.vertIndicesPerFace = vi.data();
    Descriptor::FVarChannel ch; ch.numValues = nuv; ch.valueIndices = ui.data();
    desc.numFVarChannels = 1; desc.fvarChannels = &ch;
    Far::TopologyRefiner* r = Far::TopologyRefinerFactory<Descriptor>::Create(
        desc, Far::TopologyRefinerFactory<Descriptor>::Options(Sdc::SCHEME_CATMARK, opt));
    r->RefineUniform(Far::TopologyRefiner::UniformOptions(level));
    std::vector<UV> buf(r->GetNumFVarValuesTotal());
    for (int i = 0; i < nuv; ++i) buf[i] = uv[i];
    Far::PrimvarRefiner pr(*r);
    UV* src = buf.data();
    for (int l = 1; l <= level; ++l) {
        UV* dst = src + r->GetLevel(l - 1).GetNumFVarValues(0);
        pr.InterpolateFaceVarying(l, src, dst, 0);
        src = dst;
    }
    Far::TopologyLevel const& L = r->GetLevel(level);
    int n = L.GetNumFVarValues(0);
    printf("%d\n", n);
    for (int i = 0; i < n; ++i) printf("%.17g %.17g\n", src[i].u, src[i].v);
    printf("%d\n", L.GetNumFaces());
    for (int f = 0; f < L.GetNumFaces(); ++f) {
        Far::ConstIndexArray fv = L.GetFaceFVarValues(f, 0);
        for (int k = 0; k < fv.size(); ++k) printf("%d ", fv[k]);
        printf("\n");
    }
    return 0;
}
