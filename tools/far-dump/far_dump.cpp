// Reference dumps from OpenSubdiv's Far: a shape of tests/data/opensubdiv (nonmanifold/) refined
// uniformly to level N, every level's points and the last level's limit points.
//
// Build (Debian: apt-get install libosd-dev):
//   g++ -O2 -std=c++17 tools/far-dump/far_dump.cpp -losdCPU -o /tmp/far_dump
// Run: /tmp/far_dump SHAPE.obj SCHEME N > NAME.LN.txt   (SCHEME: catmark | loop | bilinear)
//
// Output: per level k, `level k V F` then V lines `v x y z`; then the last level's limit
// points, `l x y z` (one per vertex; a vertex no face uses keeps its position), then its
// faces, `f a b c ...` (0-based). The shape's OpenSubdiv tags are read as OpenSubdiv's
// regression suite reads them: boundary rule "edges only" unless `interpolateboundary`
// says otherwise, uniform crease decrement unless `creasemethod chaikin`, Catmark triangles
// unless `smoothtriangles`.
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace OpenSubdiv;

struct Point {
    double p[3];
    void Clear(void * = nullptr) { p[0] = p[1] = p[2] = 0.0; }
    void AddWithWeight(Point const &src, double w) {
        for (int k = 0; k < 3; ++k) p[k] += w * src.p[k];
    }
};

struct Shape {
    std::vector<Point> points;
    std::vector<int> sizes, indices;
    std::vector<int> creasePairs, cornerVerts, holes;
    std::vector<float> creaseWeights, cornerWeights;
    Sdc::Options options;
};

// `t name nints/nfloats/nstrings ints... floats...`: per pair (or vertex) a float, or one for all.
static void readTag(std::istringstream &in, Shape &s) {
    std::string name, counts;
    in >> name >> counts;
    int ni = 0, nf = 0, ns = 0;
    std::sscanf(counts.c_str(), "%d/%d/%d", &ni, &nf, &ns);
    std::vector<int> ints(ni);
    std::vector<float> floats(nf);
    std::vector<std::string> strings(ns);
    for (int &i : ints) in >> i;
    for (float &f : floats) in >> f;
    for (std::string &t : strings) in >> t;
    auto weight = [&](size_t i) { return floats.size() == 1 ? floats[0] : floats[i]; };
    if (name == "crease") {
        for (size_t i = 0; i + 1 < ints.size(); i += 2) {
            s.creasePairs.push_back(ints[i]);
            s.creasePairs.push_back(ints[i + 1]);
            s.creaseWeights.push_back(weight(i / 2));
        }
    } else if (name == "corner") {
        for (size_t i = 0; i < ints.size(); ++i) {
            s.cornerVerts.push_back(ints[i]);
            s.cornerWeights.push_back(weight(i));
        }
    } else if (name == "hole") {
        s.holes.insert(s.holes.end(), ints.begin(), ints.end());
    } else if (name == "interpolateboundary" && !ints.empty()) {
        s.options.SetVtxBoundaryInterpolation(
            ints[0] == 0   ? Sdc::Options::VTX_BOUNDARY_NONE
            : ints[0] == 1 ? Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER
                           : Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    } else if (name == "creasemethod" && !strings.empty() && strings[0] == "chaikin") {
        s.options.SetCreasingMethod(Sdc::Options::CREASE_CHAIKIN);
    } else if (name == "smoothtriangles") {
        s.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_SMOOTH);
    }
}

static Shape readShape(char const *path) {
    Shape s;
    s.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    std::ifstream file(path);
    if (!file) {
        std::cerr << path << ": cannot read\n";
        std::exit(1);
    }
    std::string line;
    while (std::getline(file, line)) {
        std::istringstream in(line);
        std::string word;
        in >> word;
        if (word == "v") {
            Point p;
            in >> p.p[0] >> p.p[1] >> p.p[2];
            s.points.push_back(p);
        } else if (word == "f") {
            int n = 0;
            std::string corner;
            while (in >> corner) {
                s.indices.push_back(std::atoi(corner.c_str()) - 1);
                ++n;
            }
            s.sizes.push_back(n);
        } else if (word == "t") {
            readTag(in, s);
        }
    }
    return s;
}

int main(int argc, char **argv) {
    if (argc != 4) {
        std::cerr << "usage: far_dump SHAPE.obj catmark|loop|bilinear LEVEL\n";
        return 2;
    }
    Shape s = readShape(argv[1]);
    std::string scheme = argv[2];
    int maxLevel = std::atoi(argv[3]);
    Sdc::SchemeType type = scheme == "loop"       ? Sdc::SCHEME_LOOP
                           : scheme == "bilinear" ? Sdc::SCHEME_BILINEAR
                                                  : Sdc::SCHEME_CATMARK;
    Far::TopologyDescriptor desc;
    desc.numVertices = (int)s.points.size();
    desc.numFaces = (int)s.sizes.size();
    desc.numVertsPerFace = s.sizes.data();
    desc.vertIndicesPerFace = s.indices.data();
    desc.numCreases = (int)s.creaseWeights.size();
    desc.creaseVertexIndexPairs = s.creasePairs.data();
    desc.creaseWeights = s.creaseWeights.data();
    desc.numCorners = (int)s.cornerWeights.size();
    desc.cornerVertexIndices = s.cornerVerts.data();
    desc.cornerWeights = s.cornerWeights.data();
    desc.numHoles = (int)s.holes.size();
    desc.holeIndices = s.holes.data();
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    Far::TopologyRefiner *refiner =
        Factory::Create(desc, Factory::Options(type, s.options));
    if (!refiner) {
        std::cerr << argv[1] << ": Far refused the topology\n";
        return 1;
    }
    Far::TopologyRefiner::UniformOptions uniform(maxLevel);
    uniform.fullTopologyInLastLevel = true; // the last level's vertex faces, for the limit
    refiner->RefineUniform(uniform);
    std::vector<Point> points(refiner->GetNumVerticesTotal());
    std::copy(s.points.begin(), s.points.end(), points.begin());
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    Point *src = points.data();
    for (int k = 0; k <= maxLevel; ++k) {
        Far::TopologyLevel const &level = refiner->GetLevel(k);
        if (k > 0) {
            Point *dst = src + refiner->GetLevel(k - 1).GetNumVertices();
            primvar.Interpolate(k, src, dst);
            src = dst;
        }
        std::printf("level %d %d %d\n", k, level.GetNumVertices(), level.GetNumFaces());
        for (int v = 0; v < level.GetNumVertices(); ++v)
            std::printf("v %.10g %.10g %.10g\n", src[v].p[0], src[v].p[1], src[v].p[2]);
    }
    Far::TopologyLevel const &last = refiner->GetLevel(maxLevel);
    std::vector<Point> limit(last.GetNumVertices());
    Point *limitPoints = limit.data();
    primvar.Limit(src, limitPoints);
    for (int v = 0; v < last.GetNumVertices(); ++v) {
        Point const &p = last.GetVertexFaces(v).size() ? limit[v] : src[v];
        std::printf("l %.10g %.10g %.10g\n", p.p[0], p.p[1], p.p[2]);
    }
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        Far::ConstIndexArray fv = last.GetFaceVertices(f);
        std::printf("f");
        for (int i = 0; i < fv.size(); ++i) std::printf(" %d", fv[i]);
        std::printf("\n");
    }
    delete refiner;
    return 0;
}
