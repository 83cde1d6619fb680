// Reference values of the limit surface from OpenSubdiv (Far/Vtr/Sdc, CPU, double precision).
//
// Build (Debian libosd-dev 3.5.0):  g++ -O2 -std=c++14 driver.cpp -o osd_driver -losdCPU
// Run:                              ./osd_driver MESH.obj|MESH.off SEED > osd_limit_MESH.json
//
// Reads the vertices and faces of an OBJ (v/f lines; any /vt/vn suffix ignored; OpenSubdiv's `t`
// tag lines: crease, corner, hole, interpolateboundary, creasemethod) or OFF file, all vertices kept
// (unused ones too), 0-based in file order. Sdc::SCHEME_CATMARK, boundary interpolation and creasing
// method from the tags (default VTX_BOUNDARY_EDGE_ONLY, CREASE_UNIFORM). No samples on holes. TopologyRefinerFactory<TopologyDescriptor> (default options: no full
// topology validation, as OpenSubdiv's own tools), RefineAdaptive(isolation 10, useInfSharpPatch),
// PatchTableFactory (ENDCAP_GREGORY_BASIS, useInfSharpPatch, generateLegacySharpCornerPatches=false,
// useSingleCreasePatch=false, double-precision stencils), PrimvarRefiner + local point stencils for
// the refined points, PatchMap to locate (ptex face, s, t), PatchTable::EvaluateBasis for P and the
// first derivatives (second derivatives are computed, not written). Samples: per ptex face the 3x3
// grid s,t in {0,1/2,1}, the points (2^-k, 2^-k-1) and their images at each corner for k = 2,4,..,12,
// and 4 random points (std::mt19937_64 seeded with SEED).
// Also the level-0 tags OpenSubdiv assigned (non-manifold edges/vertices, sharpness, vertex rule), and
// the points of two uniform steps (PrimvarRefiner): vertex_points[l][v] the vertex point of vertex v
// after l + 1 steps, edge_points[e] the edge point of level-0 edge e (same order as edges).
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/version.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace OpenSubdiv;
typedef Far::TopologyDescriptor Descriptor;

struct Pt {
    double x[3];
    void Clear() { x[0] = x[1] = x[2] = 0; }
    void AddWithWeight(Pt const &p, double w) {
        for (int i = 0; i < 3; ++i) x[i] += w * p.x[i];
    }
};

struct Tags {
    std::vector<int> creasePairs, corners, holes;
    std::vector<float> creaseWeights, cornerWeights;
    int boundary = 2;  // OBJ tag value: 0 none, 1 edge and corner, 2 edge only (default)
    bool chaikin = false;
};

// OpenSubdiv's OBJ tag lines (regression/common/shape_utils.cpp grammar), 0-based indices:
// t crease n/1/0 a b [c d ..] s | n/(n/2)/0 (one float per pair); t corner n/1/0 v.. s | n/n/0;
// t hole n/0/0 f..; t interpolateboundary 1/0/0 m; t creasemethod 0/0/1 normal|chaikin.
// Negative sharpness is clamped to 0 (shape_utils does so).
static void parseTag(std::istringstream &ss, Tags &tags) {
    std::string name, counts;
    ss >> name >> counts;
    int ni = 0, nf = 0, ns = 0;
    sscanf(counts.c_str(), "%d/%d/%d", &ni, &nf, &ns);
    std::vector<int> ints(ni);
    std::vector<float> floats(nf);
    std::vector<std::string> strs(ns);
    for (int &i : ints) ss >> i;
    for (float &f : floats) { ss >> f; if (f < 0) f = 0; }
    for (std::string &x : strs) ss >> x;
    if (name == "crease") {
        for (int j = 0; j + 1 < ni; j += 2) {
            tags.creasePairs.push_back(ints[j]);
            tags.creasePairs.push_back(ints[j + 1]);
            tags.creaseWeights.push_back(nf > 1 ? floats[j / 2] : floats[0]);
        }
    } else if (name == "corner") {
        for (int j = 0; j < ni; ++j) {
            tags.corners.push_back(ints[j]);
            tags.cornerWeights.push_back(nf > 1 ? floats[j] : floats[0]);
        }
    } else if (name == "hole") {
        for (int i : ints) tags.holes.push_back(i);
    } else if (name == "interpolateboundary") {
        tags.boundary = ints[0];
    } else if (name == "creasemethod") {
        tags.chaikin = (strs[0] == "chaikin");
    } else {
        fprintf(stderr, "tag %s not supported\n", name.c_str());
        exit(2);
    }
}

static void readMesh(const std::string &path, std::vector<double> &V, std::vector<int> &sizes,
                     std::vector<int> &idx, Tags &tags) {
    std::ifstream in(path);
    if (!in) { fprintf(stderr, "cannot open %s\n", path.c_str()); exit(2); }
    bool off = path.size() > 4 && path.substr(path.size() - 4) == ".off";
    std::string line;
    if (off) {
        std::vector<std::string> toks;
        while (std::getline(in, line)) {
            size_t h = line.find('#');
            if (h != std::string::npos) line = line.substr(0, h);
            std::istringstream ss(line);
            std::string t;
            while (ss >> t) toks.push_back(t);
        }
        size_t k = 0;
        if (toks[k] == "OFF") ++k;
        int nv = atoi(toks[k++].c_str()), nf = atoi(toks[k++].c_str());
        ++k;  // edges
        for (int i = 0; i < 3 * nv; ++i) V.push_back(strtod(toks[k++].c_str(), 0));
        for (int f = 0; f < nf; ++f) {
            int n = atoi(toks[k++].c_str());
            sizes.push_back(n);
            for (int i = 0; i < n; ++i) idx.push_back(atoi(toks[k++].c_str()));
        }
        return;
    }
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::string tag;
        if (!(ss >> tag)) continue;
        if (tag == "v") {
            std::string a, b, c;
            ss >> a >> b >> c;
            V.push_back(strtod(a.c_str(), 0));
            V.push_back(strtod(b.c_str(), 0));
            V.push_back(strtod(c.c_str(), 0));
        } else if (tag == "f") {
            std::string t;
            int n = 0;
            while (ss >> t) {
                idx.push_back(atoi(t.substr(0, t.find('/')).c_str()) - 1);
                ++n;
            }
            sizes.push_back(n);
        } else if (tag == "t") {
            parseTag(ss, tags);
        }
    }
}

static void put(const double *p) {
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) { printf("null"); return; }
    printf("[%.17g, %.17g, %.17g]", p[0], p[1], p[2]);
}

int main(int argc, char **argv) {
    if (argc < 3) { fprintf(stderr, "usage: %s MESH SEED\n", argv[0]); return 2; }
    std::vector<double> V;
    std::vector<int> sizes, idx;
    Tags tags;
    readMesh(argv[1], V, sizes, idx, tags);
    int nv = (int)V.size() / 3, nf = (int)sizes.size();

    Sdc::Options sdc;
    Sdc::Options::VtxBoundaryInterpolation modes[3] = {Sdc::Options::VTX_BOUNDARY_NONE,
        Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER, Sdc::Options::VTX_BOUNDARY_EDGE_ONLY};
    sdc.SetVtxBoundaryInterpolation(modes[tags.boundary]);
    sdc.SetCreasingMethod(tags.chaikin ? Sdc::Options::CREASE_CHAIKIN : Sdc::Options::CREASE_UNIFORM);
    Descriptor desc;
    desc.numVertices = nv;
    desc.numFaces = nf;
    desc.numVertsPerFace = sizes.data();
    desc.vertIndicesPerFace = idx.data();
    desc.numCreases = (int)tags.creaseWeights.size();
    desc.creaseVertexIndexPairs = tags.creasePairs.data();
    desc.creaseWeights = tags.creaseWeights.data();
    desc.numCorners = (int)tags.cornerWeights.size();
    desc.cornerVertexIndices = tags.corners.data();
    desc.cornerWeights = tags.cornerWeights.data();
    desc.numHoles = (int)tags.holes.size();
    desc.holeIndices = tags.holes.data();
    Far::TopologyRefiner *refiner = Far::TopologyRefinerFactory<Descriptor>::Create(
        desc, Far::TopologyRefinerFactory<Descriptor>::Options(Sdc::SCHEME_CATMARK, sdc));
    if (!refiner) { fprintf(stderr, "OpenSubdiv refused the mesh\n"); return 3; }

    // level-0 tags before refinement
    Far::TopologyLevel const &L0 = refiner->GetLevel(0);
    std::vector<int> nmVerts, nmEdges;
    std::vector<float> vSharp(nv);
    std::vector<int> vRule(nv);
    for (int v = 0; v < nv; ++v) {
        if (L0.IsVertexNonManifold(v)) nmVerts.push_back(v);
        vSharp[v] = L0.GetVertexSharpness(v);
        vRule[v] = (int)L0.GetVertexRule(v);
    }
    for (int e = 0; e < L0.GetNumEdges(); ++e)
        if (L0.IsEdgeNonManifold(e)) nmEdges.push_back(e);
    std::vector<int> edgeVerts;
    std::vector<float> eSharp;
    for (int e = 0; e < L0.GetNumEdges(); ++e) {
        Far::ConstIndexArray ev = L0.GetEdgeVertices(e);
        edgeVerts.push_back(ev[0]);
        edgeVerts.push_back(ev[1]);
        eSharp.push_back(L0.GetEdgeSharpness(e));
    }
    int nEdges0 = L0.GetNumEdges();

    // the vertex points of two uniform steps (PrimvarRefiner): per level-0 vertex its child and grandchild,
    // per level-0 edge its edge point (level 1)
    Far::TopologyRefiner *uni = Far::TopologyRefinerFactory<Descriptor>::Create(
        desc, Far::TopologyRefinerFactory<Descriptor>::Options(Sdc::SCHEME_CATMARK, sdc));
    uni->RefineUniform(Far::TopologyRefiner::UniformOptions(2));
    std::vector<Pt> uv(uni->GetNumVerticesTotal());
    for (int i = 0; i < nv; ++i)
        for (int j = 0; j < 3; ++j) uv[i].x[j] = V[3 * i + j];
    Far::PrimvarRefinerReal<double> uprim(*uni);
    int n1 = uni->GetLevel(1).GetNumVertices();
    Pt *u0 = &uv[0], *u1 = &uv[nv], *u2 = &uv[nv + n1];
    uprim.Interpolate(1, u0, u1);
    uprim.Interpolate(2, u1, u2);

    const int level = 10;
    Far::TopologyRefiner::AdaptiveOptions aopts(level);
    aopts.useInfSharpPatch = true;
    refiner->RefineAdaptive(aopts);

    Far::PatchTableFactory::Options popts(level);
    popts.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
    popts.useInfSharpPatch = true;
    popts.generateLegacySharpCornerPatches = false;
    popts.useSingleCreasePatch = false;
    popts.SetPatchPrecision<double>();
    Far::PatchTable const *table = Far::PatchTableFactory::Create(*refiner, popts);

    int nRefined = refiner->GetNumVerticesTotal();
    int nLocal = table->GetNumLocalPoints();
    std::vector<Pt> verts(nRefined + nLocal);
    for (int i = 0; i < nv; ++i)
        for (int j = 0; j < 3; ++j) verts[i].x[j] = V[3 * i + j];
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    Pt *src = &verts[0];
    for (int l = 1; l <= refiner->GetMaxLevel(); ++l) {
        Pt *dst = src + refiner->GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    if (nLocal) table->GetLocalPointStencilTable<double>()->UpdateValues(&verts[0], &verts[nRefined]);

    Far::PtexIndices ptex(*refiner);
    Far::PatchMap pmap(*table);

    std::vector<double> S, T;
    std::vector<int> F;
    std::mt19937_64 rng(strtoull(argv[2], 0, 10));
    std::uniform_real_distribution<double> U(0.0, 1.0);
    int nptex = ptex.GetNumFaces();
    for (int p = 0; p < nptex; ++p) {
        for (int i = 0; i <= 2; ++i)
            for (int j = 0; j <= 2; ++j) { F.push_back(p); S.push_back(i / 2.0); T.push_back(j / 2.0); }
        for (int k = 2; k <= 12; k += 2) {
            double a = std::ldexp(1.0, -k), b = std::ldexp(1.0, -k - 1);
            double cs[4][2] = {{a, b}, {1 - a, b}, {1 - b, 1 - a}, {b, 1 - a}};
            for (auto &c : cs) { F.push_back(p); S.push_back(c[0]); T.push_back(c[1]); }
        }
        for (int r = 0; r < 4; ++r) { F.push_back(p); S.push_back(U(rng)); T.push_back(U(rng)); }
    }

    printf("{\n  \"generator\": \"tests/data/osd_nonmanifold/driver.cpp\",\n");
    printf("  \"opensubdiv_version\": \"%s\",\n", "3.5.0 (Debian libosd-dev 3.5.0-2, OPENSUBDIV_VERSION_NUMBER 30500)");
    printf("  \"mesh\": \"%s\",\n", argv[1]);
    const char *modeNames[3] = {"VTX_BOUNDARY_NONE", "VTX_BOUNDARY_EDGE_AND_CORNER", "VTX_BOUNDARY_EDGE_ONLY"};
    printf("  \"settings\": {\"scheme\": \"CATMARK\", \"boundary\": \"%s\", \"crease\": \"%s\", ",
           modeNames[tags.boundary], tags.chaikin ? "CREASE_CHAIKIN" : "CREASE_UNIFORM");
    printf(
           "\"isolation_level\": %d, \"end_cap\": \"ENDCAP_GREGORY_BASIS\", \"useInfSharpPatch\": true, "
           "\"generateLegacySharpCornerPatches\": false, \"useSingleCreasePatch\": false, \"precision\": \"double\", "
           "\"seed\": %s},\n", level, argv[2]);
    printf("  \"num_vertices\": %d, \"num_faces\": %d, \"num_ptex_faces\": %d, \"num_edges\": %d,\n", nv, nf, nptex, nEdges0);
    printf("  \"nonmanifold_vertices\": [");
    for (size_t i = 0; i < nmVerts.size(); ++i) printf("%s%d", i ? ", " : "", nmVerts[i]);
    printf("],\n  \"nonmanifold_edges\": [");
    for (size_t i = 0; i < nmEdges.size(); ++i)
        printf("%s[%d, %d]", i ? ", " : "", edgeVerts[2 * nmEdges[i]], edgeVerts[2 * nmEdges[i] + 1]);
    printf("],\n  \"vertex_sharpness\": [");
    for (int v = 0; v < nv; ++v) printf("%s%.9g", v ? ", " : "", vSharp[v]);
    printf("],\n  \"vertex_rule\": [");
    const char *rules[] = {"unknown", "smooth", "dart", "", "crease", "", "", "", "corner"};  // Sdc::Crease::Rule bits
    for (int v = 0; v < nv; ++v) printf("%s\"%s\"", v ? ", " : "", (vRule[v] >= 0 && vRule[v] <= 8) ? rules[vRule[v]] : "?");
    printf("],\n  \"edges\": [");
    for (int e = 0; e < nEdges0; ++e)
        printf("%s[%d, %d, %.9g]", e ? ", " : "", edgeVerts[2 * e], edgeVerts[2 * e + 1], eSharp[e]);
    printf("],\n  \"faces\": [");
    for (int f = 0; f < nf; ++f) printf("%s{\"size\": %d, \"ptex\": %d}", f ? ", " : "", sizes[f], ptex.GetFaceId(f));
    printf("],\n  \"vertex_points\": [[");
    Far::TopologyLevel const &U0 = uni->GetLevel(0), &U1 = uni->GetLevel(1);
    double nan3[3] = {NAN, NAN, NAN};
    for (int v = 0; v < nv; ++v) {
        int c = U0.GetVertexChildVertex(v);
        printf(v ? ", " : "");
        put(c < 0 ? nan3 : uv[nv + c].x);
    }
    printf("], [");
    for (int v = 0; v < nv; ++v) {
        int c = U0.GetVertexChildVertex(v), g = c < 0 ? -1 : U1.GetVertexChildVertex(c);
        printf(v ? ", " : "");
        put(g < 0 ? nan3 : uv[nv + n1 + g].x);
    }
    printf("]],\n  \"edge_points\": [");
    for (int e = 0; e < nEdges0; ++e) { printf(e ? ", " : ""); put(uv[nv + U0.GetEdgeChildVertex(e)].x); }
    printf("],\n  \"samples\": [\n");
    double wP[20], wDs[20], wDt[20], wDss[20], wDst[20], wDtt[20];
    int written = 0;
    for (size_t i = 0; i < F.size(); ++i) {
        double s = S[i], t = T[i];
        Far::PatchTable::PatchHandle const *h = pmap.FindPatch(F[i], s, t);
        if (!h) continue;  // a hole (tagged, or implicit under VTX_BOUNDARY_NONE): no surface
        if (written++) printf(",\n");
        table->EvaluateBasis(*h, s, t, wP, wDs, wDt, wDss, wDst, wDtt);
        Far::ConstIndexArray cvs = table->GetPatchVertices(*h);
        Far::PatchParam param = table->GetPatchParam(*h);
        Far::PatchDescriptor::Type type = table->GetPatchDescriptor(*h).GetType();
        double P[3] = {0, 0, 0}, Ps[3] = {0, 0, 0}, Pt[3] = {0, 0, 0}, Pss[3] = {0, 0, 0}, Pst[3] = {0, 0, 0},
               Ptt[3] = {0, 0, 0};
        for (int c = 0; c < cvs.size(); ++c) {
            const double *x = verts[cvs[c]].x;
            for (int j = 0; j < 3; ++j) {
                P[j] += wP[c] * x[j];
                Ps[j] += wDs[c] * x[j];
                Pt[j] += wDt[c] * x[j];
                Pss[j] += wDss[c] * x[j];
                Pst[j] += wDst[c] * x[j];
                Ptt[j] += wDtt[c] * x[j];
            }
        }
        // EvaluateBasis scales by 2^depth also under an n-gon, whose patches span 2^-(depth-1)
        // of the ptex sub-face: divide to get derivatives with respect to the ptex (s, t)
        if (param.NonQuadRoot()) {
            for (int j = 0; j < 3; ++j) {
                Ps[j] /= 2; Pt[j] /= 2; Pss[j] /= 4; Pst[j] /= 4; Ptt[j] /= 4;
            }
        }
        bool exact = (type == Far::PatchDescriptor::REGULAR);
        printf("    {\"ptex\": %d, \"s\": %.17g, \"t\": %.17g, \"exact\": %s, \"patch_depth\": %d, \"P\": ", F[i], s, t,
               exact ? "true" : "false", param.GetDepth());
        put(P); printf(", \"Ps\": "); put(Ps); printf(", \"Pt\": "); put(Pt);
        printf("}");
    }
    printf("\n  ]\n}\n");
    delete table;
    delete refiner;
    delete uni;
    return 0;
}
