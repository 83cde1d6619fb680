// OpenSubdiv Far's setup as a program of its own, for scripts/bench_evaluate.py --setup-only: a fresh
// process that reads an OBJ file (v and f lines, and OpenSubdiv's `t` tag lines with the grammar of its
// regression/common/shape_utils.cpp: crease, corner, hole, interpolateboundary, creasemethod,
// smoothtriangles; face-varying tags ignored), builds the TopologyRefiner, refines adaptively to level 10,
// builds the PatchTable with Gregory end caps (double), its local points and the PatchMap: the same work as
// far_create of scripts/osd_capi.cpp. Built by scripts/_osd.py with `g++ -O2 osd_setup_driver.cpp -losdCPU`.
//
// Usage: osd_setup_driver MESH.obj FACE S T
// Prints one line: the number of ptex faces, of patches, and P at ptex face FACE, (S, T) (for the check
// that this reader and the in-process C API see the same mesh).
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
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

float clamp_sharpness(float s) { return std::min(std::max(s, 0.0f), 10.0f); }

}  // namespace

int main(int argc, char **argv) {
    if (argc != 5) {
        std::fprintf(stderr, "usage: %s MESH.obj FACE S T\n", argv[0]);
        return 2;
    }
    std::ifstream in(argv[1]);
    if (!in) {
        std::fprintf(stderr, "cannot read %s\n", argv[1]);
        return 2;
    }
    std::vector<double> X;
    std::vector<int> sizes, idx, cre, cor, holes;
    std::vector<float> cw, kw;
    Sdc::Options so;
    so.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string key;
        if (!(ls >> key)) continue;
        if (key == "v") {
            double x, y, z;
            ls >> x >> y >> z;
            X.push_back(x), X.push_back(y), X.push_back(z);
        } else if (key == "f") {
            std::string tok;
            int n = 0;
            while (ls >> tok) {
                int i = std::atoi(tok.substr(0, tok.find('/')).c_str());
                idx.push_back(i > 0 ? i - 1 : (int)(X.size() / 3) + i);
                ++n;
            }
            sizes.push_back(n);
        } else if (key == "t") {
            std::string name, counts;
            ls >> name >> counts;
            int ni = 0, nf = 0, ns = 0;
            std::sscanf(counts.c_str(), "%d/%d/%d", &ni, &nf, &ns);
            std::vector<int> ints(ni);
            std::vector<float> floats(nf);
            std::vector<std::string> strings(ns);
            for (auto &a : ints) ls >> a;
            for (auto &a : floats) ls >> a;
            for (auto &a : strings) ls >> a;
            if (name == "crease") {
                for (int j = 0; j + 1 < ni; j += 2) {
                    cre.push_back(ints[j]), cre.push_back(ints[j + 1]);
                    cw.push_back(clamp_sharpness(nf > 1 && j < nf ? floats[j] : floats[0]));
                }
            } else if (name == "corner") {
                for (int j = 0; j < ni; ++j) {
                    cor.push_back(ints[j]);
                    kw.push_back(clamp_sharpness(nf > 1 && j < nf ? floats[j] : floats[0]));
                }
            } else if (name == "hole") {
                holes.insert(holes.end(), ints.begin(), ints.end());
            } else if (name == "interpolateboundary") {
                so.SetVtxBoundaryInterpolation(ints[0] == 0   ? Sdc::Options::VTX_BOUNDARY_NONE
                                               : ints[0] == 1 ? Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER
                                                              : Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
            } else if (name == "creasemethod") {
                if (strings[0] == "chaikin") so.SetCreasingMethod(Sdc::Options::CREASE_CHAIKIN);
            } else if (name == "smoothtriangles") {
                if (strings[0] == "smooth") so.SetTriangleSubdivision(Sdc::Options::TRI_SUB_SMOOTH);
            }
        }
    }
    Far::TopologyDescriptor d;
    d.numVertices = (int)(X.size() / 3);
    d.numFaces = (int)sizes.size();
    d.numVertsPerFace = sizes.data();
    d.vertIndicesPerFace = idx.data();
    d.numCreases = (int)cw.size();
    d.creaseVertexIndexPairs = cre.data();
    d.creaseWeights = cw.data();
    d.numCorners = (int)kw.size();
    d.cornerVertexIndices = cor.data();
    d.cornerWeights = kw.data();
    d.numHoles = (int)holes.size();
    d.holeIndices = holes.data();
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    Far::TopologyRefiner *ref = Factory::Create(d, Factory::Options(Sdc::SCHEME_CATMARK, so));
    if (!ref) {
        std::fprintf(stderr, "OpenSubdiv refused the mesh\n");
        return 1;
    }
    Far::PatchTableFactory::Options po(10);
    po.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    po.SetPatchPrecision<double>();
    po.useInfSharpPatch = true;
    po.generateLegacySharpCornerPatches = false;
    ref->RefineAdaptive(po.GetRefineAdaptiveOptions());
    Far::PatchTable *tab = Far::PatchTableFactory::Create(*ref, po);
    int nref = ref->GetNumVerticesTotal(), nloc = tab->GetNumLocalPoints();
    std::vector<V3> V(nref + nloc);
    for (int i = 0; i < d.numVertices; ++i)
        for (int c = 0; c < 3; ++c) V[i].p[c] = X[3 * i + c];
    Far::PrimvarRefinerReal<double> pr(*ref);
    V3 *src = V.data();
    for (int l = 1; l <= ref->GetMaxLevel(); ++l) {
        V3 *dst = src + ref->GetLevel(l - 1).GetNumVertices();
        pr.Interpolate(l, src, dst);
        src = dst;
    }
    if (nloc) tab->GetLocalPointStencilTable<double>()->UpdateValues(V.data(), V.data() + nref);
    Far::PatchMap pmap(*tab);
    // the check point
    int face = std::atoi(argv[2]);
    double s = std::atof(argv[3]), t = std::atof(argv[4]), w[20], ws[20], wt[20], P[3] = {0, 0, 0};
    Far::PatchTable::PatchHandle const *ph = pmap.FindPatch(face, s, t);
    if (ph) {
        tab->EvaluateBasis(*ph, s, t, w, ws, wt);
        Far::ConstIndexArray cv = tab->GetPatchVertices(*ph);
        for (int j = 0; j < cv.size(); ++j)
            for (int c = 0; c < 3; ++c) P[c] += w[j] * V[cv[j]].p[c];
    }
    Far::PtexIndices ptex(*ref);
    std::printf("%d %d %.17g %.17g %.17g\n", ptex.GetNumFaces(), tab->GetNumPatchesTotal(), P[0], P[1], P[2]);
    delete tab;
    delete ref;
    return 0;
}
