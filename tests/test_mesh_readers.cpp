// The PLY, OFF, STL, OBJ and VRML readers behind LoadMesh: hostile files (lying counts, bad indices,
// truncation, huge polygons, special files, numbers with garbage) give one clear error, and valid
// files give exactly the mesh vcglib's importers give.
#include <gtest/gtest.h>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/io/mesh_io.h>
#include <wrap/io_trimesh/import_off.h>
#include <wrap/io_trimesh/import_ply.h>
#include <wrap/io_trimesh/import_stl.h>

#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "test_helpers.h"

namespace {

using molremesh::MeshD;
using molremesh::test::SharedMesh;
using molremesh::test::TempDir;

struct Loaded {
  bool ok = false;
  std::string error;
  MeshD mesh;
};

class MeshReaders : public ::testing::Test {
protected:
  void SetUp() override { dir_ = TempDir("mesh_readers"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& content) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }
  static std::unique_ptr<Loaded> Load(const std::string& path) {
    auto result = std::make_unique<Loaded>();
    result->ok = molremesh::LoadMesh(result->mesh, path, result->error);
    return result;
  }
  /// Loading fails with one line that names the file and contains `what`; the mesh is empty.
  static void ExpectRefused(const std::string& path, const std::string& what) {
    const auto r = Load(path);
    EXPECT_FALSE(r->ok) << path << " was read: " << r->mesh.vn << " vertices, " << r->mesh.fn << " faces";
    EXPECT_EQ(r->mesh.vn, 0);
    EXPECT_EQ(r->mesh.fn, 0);
    EXPECT_NE(r->error.find("'" + path + "'"), std::string::npos) << r->error;
    EXPECT_NE(r->error.find(what), std::string::npos) << "expected '" << what << "' in: " << r->error;
    EXPECT_EQ(r->error.find('\n'), std::string::npos) << r->error;
  }
  std::filesystem::path dir_;
};

const std::string kXyz = "property float x\nproperty float y\nproperty float z\n";
const std::string kFaceList = "property list uchar int vertex_indices\n";
const std::string kSquare = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

std::string AsciiPly(int vertices, int faces, const std::string& body) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) + "\n" + kXyz + "element face " +
         std::to_string(faces) + "\n" + kFaceList + "end_header\n" + body;
}

/// A binary little-endian PLY of the unit square's 4 vertices and the faces given as index lists.
std::string BinaryPly(const std::vector<std::vector<int>>& faces, const std::string& countType = "uchar") {
  std::string out = "ply\nformat binary_little_endian 1.0\nelement vertex 4\n" + kXyz + "element face " +
                    std::to_string(faces.size()) + "\nproperty list " + countType +
                    " int vertex_indices\nend_header\n";
  const float xyz[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  out.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  for (const auto& f : faces) {
    if (countType == "uchar") {
      out += char(static_cast<unsigned char>(f.size()));
    } else {
      const std::int32_t n = std::int32_t(f.size());
      out.append(reinterpret_cast<const char*>(&n), 4);
    }
    out.append(reinterpret_cast<const char*>(f.data()), 4 * f.size());
  }
  return out;
}

// --- PLY -----------------------------------------------------------------------------------------

TEST_F(MeshReaders, PlyElementWithoutACountIsRefused) {
  ExpectRefused(
      Write("nocount.ply", "ply\nformat ascii 1.0\nelement vertex\n" + kXyz + "end_header\n0 0 0\n"),
      "'element' without a name and a count");
  ExpectRefused(Write("minus.ply", AsciiPly(-1, 0, "")), "bad count '-1'");
  ExpectRefused(Write("word.ply", "ply\nformat ascii 1.0\nelement vertex many\n" + kXyz + "end_header\n"),
                "bad count 'many'");
}

TEST_F(MeshReaders, PlyPolygonWhoseLastIndexIsOutOfRangeIsRefused) {
  ExpectRefused(Write("last.ply", AsciiPly(4, 1, kSquare + "4 0 1 2 4\n")), "refers to vertex 4 of 4");
  ExpectRefused(Write("lastbin.ply", BinaryPly({{0, 1, 2, 3}, {0, 1, 2, 99}})), "refers to vertex 99 of 4");
  ExpectRefused(Write("negative.ply", AsciiPly(4, 1, kSquare + "3 0 -1 2\n")), "refers to vertex -1 of 4");
}

TEST_F(MeshReaders, PlyFaceListsBeyondTheCornerLimitAreRefusedAsciiAndBinary) {
  std::vector<int> ring;
  for (int i = 0; i < 600; ++i) ring.push_back(i % 4);
  std::string ascii = kSquare + "600";
  for (int i : ring) ascii += " " + std::to_string(i);
  std::string longPly = AsciiPly(4, 1, ascii + "\n");
  longPly.replace(longPly.find("list uchar"), 10, "list int");
  ExpectRefused(Write("long.ply", longPly), "600 corners (3 to 256 supported)");
  ExpectRefused(Write("uchar.ply", AsciiPly(4, 1, ascii + "\n")),
                "bad integer '600'"); // beyond its count type
  ExpectRefused(Write("longbin.ply", BinaryPly({ring}, "int")), "600 corners");
  ExpectRefused(Write("short.ply", AsciiPly(4, 1, kSquare + "2 0 1\n")), "2 corners");
  ExpectRefused(Write("zero.ply", BinaryPly({{}})), "0 corners");
  // At the limit a polygon is read, as a fan.
  ring.resize(molremesh::kMaxPolygonCorners);
  const auto r = Load(Write("limit.ply", BinaryPly({ring}, "int")));
  ASSERT_TRUE(r->ok) << r->error;
  EXPECT_EQ(r->mesh.fn, int(molremesh::kMaxPolygonCorners) - 2);
}

TEST_F(MeshReaders, PlyTriangleStripsAreReadWithEveryIndexChecked) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 5\n" + kXyz +
                             "element tristrips 1\nproperty list int int vertex_indices\nend_header\n" +
                             kSquare + "2 2 2\n";
  const auto good = Load(Write("strip.ply", header + "7 0 1 2 3 -1 2 4\n"));
  ASSERT_TRUE(good->ok) << good->error;
  ASSERT_EQ(good->mesh.fn, 2);
  // Every other triangle of a strip is flipped to keep one orientation.
  EXPECT_EQ(good->mesh.face[1].V(0) - &good->mesh.vert[0], 2);
  EXPECT_EQ(good->mesh.face[1].V(1) - &good->mesh.vert[0], 1);
  ExpectRefused(Write("stripbad.ply", header + "5 0 1 2 3 77\n"), "refers to vertex 77 of 5");
  ExpectRefused(Write("stripneg.ply", header + "4 0 1 -2 3\n"), "refers to vertex -2 of 5");
}

TEST_F(MeshReaders, PlyCountsBeyondTheFileSizeAreRefusedBeforeAllocating) {
  ExpectRefused(Write("manyv.ply", AsciiPly(300000000, 1, kSquare + "3 0 1 2\n")), "(truncated or corrupt)");
  ExpectRefused(Write("manyf.ply", AsciiPly(4, 2000000000, kSquare + "3 0 1 2\n")), "but the file has");
  // Fewer elements declared than the file holds: the counts lie, nothing is silently dropped.
  ExpectRefused(Write("fewer.ply", AsciiPly(4, 1, kSquare + "3 0 1 2\n3 0 2 3\n")),
                "data after the last declared");
  std::string fewer = BinaryPly({{0, 1, 2}, {0, 2, 3}});
  fewer.replace(fewer.find("element face 2"), 14, "element face 1");
  ExpectRefused(Write("fewerbin.ply", fewer), "data after the last declared element at byte 61");
  ExpectRefused(Write("fewer.off", "OFF\n4 1 0\n" + kSquare + "3 0 1 2\n3 0 2 3\n"),
                "data after the last of the 1");
  std::string huge = BinaryPly({{0, 1, 2}});
  huge.replace(huge.find("element face 1"), 14, "element face 4294967296");
  ExpectRefused(Write("hugef.ply", huge), "more than supported");
  // An element other than vertex and face with a count near 2^63 (found by fuzzing): the byte count
  // it needs is said as text, never cast out of an integer's range.
  std::string extra = BinaryPly({{0, 1, 2}});
  extra.replace(extra.find("end_header"), 10,
                "element extra 9223372036854775807\nproperty double a\nproperty double b\nend_header");
  ExpectRefused(Write("hugeextra.ply", extra), "at least 10^18 bytes");
}

TEST_F(MeshReaders, PlyTruncatedAtAnyOffsetIsRefusedAndNeverReadShort) {
  for (const std::string& full :
       {BinaryPly({{0, 1, 2}, {0, 2, 3}}), AsciiPly(4, 2, kSquare + "3 0 1 2\n3 0 2 3\n")}) {
    for (std::size_t size = 1; size < full.size(); ++size) {
      const auto r = Load(Write("cut.ply", full.substr(0, size)));
      // Only the final newline of an ascii file may go; everything shorter is an error.
      if (r->ok) {
        EXPECT_EQ(r->mesh.fn, 2) << "cut at " << size;
        EXPECT_EQ(size, full.size() - 1);
      } else {
        EXPECT_EQ(r->error.find('\n'), std::string::npos);
      }
    }
  }
}

TEST_F(MeshReaders, PlyWrongPropertyTypesAndGarbageNumbersAreRefused) {
  ExpectRefused(Write("intx.ply",
                      "ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\n"
                      "property float z\nend_header\n0 0 0\n"),
                "'x' must be a float or double");
  ExpectRefused(
      Write("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n"),
      "unknown type 'float128'");
  ExpectRefused(
      Write("floatlist.ply", "ply\nformat ascii 1.0\nelement vertex 4\n" + kXyz +
                                 "element face 1\nproperty list float int vertex_indices\nend_header\n"),
      "integer count type");
  ExpectRefused(Write("garbage.ply", AsciiPly(4, 1, "0 0 0\n1 0 0\n1 1x 0\n0 1 0\n3 0 1 2\n")),
                "'1x' at line 12");
  ExpectRefused(Write("fracindex.ply", AsciiPly(4, 1, kSquare + "3 0 1.5 2\n")), "bad integer '1.5'");
  ExpectRefused(Write("ucharrange.ply", AsciiPly(4, 1, kSquare + "300 0 1 2\n")), "bad integer '300'");
  ExpectRefused(Write("format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
                "unknown PLY format");
  ExpectRefused(Write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"), "no end_header");
}

TEST_F(MeshReaders, PlyBigEndianDoublesAndSkippedListsReadTheSameMesh) {
  std::string big =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\nproperty list uchar float normals\nelement face 1\n"
      "property uint8 flags\nproperty list uint16 uint32 vertex_index\nend_header\n";
  auto putBig = [&](const void* data, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) big += static_cast<const char*>(data)[i];
  };
  const double xyz[9] = {0.1, 0.2, 0.3, 1e-300, 2.5, -3, 7, 8, 9};
  for (int v = 0; v < 3; ++v) {
    for (int c = 0; c < 3; ++c) putBig(&xyz[3 * v + c], 8);
    big += char(2);
    const float n[2] = {1, 2};
    putBig(&n[0], 4);
    putBig(&n[1], 4);
  }
  big += char(5);
  const std::uint16_t three = 3;
  putBig(&three, 2);
  for (std::uint32_t i : {2u, 0u, 1u}) putBig(&i, 4);
  const auto r = Load(Write("big.ply", big));
  ASSERT_TRUE(r->ok) << r->error;
  ASSERT_EQ(r->mesh.vn, 3);
  ASSERT_EQ(r->mesh.fn, 1);
  for (int v = 0; v < 3; ++v)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(r->mesh.vert[std::size_t(v)].P()[c], xyz[3 * v + c]);
  EXPECT_EQ(r->mesh.face[0].V(0), &r->mesh.vert[2]);
}

// --- OFF -----------------------------------------------------------------------------------------

TEST_F(MeshReaders, OffFaceIndicesAreBoundsChecked) {
  ExpectRefused(Write("tri.off", "OFF\n4 1 0\n" + kSquare + "3 0 1 4\n"), "refers to vertex '4' of 4");
  ExpectRefused(Write("quad.off", "OFF\n4 1 0\n" + kSquare + "4 0 1 2 100000000\n"), "'100000000' of 4");
  ExpectRefused(Write("neg.off", "OFF\n4 1 0\n" + kSquare + "3 0 -1 2\n"), "'-1' of 4");
}

TEST_F(MeshReaders, OffTruncatedAfterTheVerticesIsRefused) {
  ExpectRefused(Write("cut.off", "OFF\n4 2 0\n" + kSquare), "(truncated or corrupt)"); // by its size
  const std::string square = "0.0 0.0 0.0\n1.0 0.0 0.0\n1.0 1.0 0.0\n0.0 1.0 0.0\n";
  ExpectRefused(Write("cut2.off", "OFF\n4 2 0\n" + square), "ends after 0 of 2 faces (truncated)");
  ExpectRefused(Write("cutv.off", "OFF\n4 0 0\n" + square.substr(0, 30)), "ends inside vertex 2 (truncated)");
  ExpectRefused(Write("cutf.off", "OFF\n4 1 0\n" + square + "4 0 1"), "ends inside face 0 (truncated)");
}

TEST_F(MeshReaders, OffCountsSizesAndCoordinatesAreValidated) {
  ExpectRefused(Write("negcount.off", "OFF\n-1 1 0\n" + kSquare), "bad OFF counts");
  ExpectRefused(Write("many.off", "OFF\n4 1000000000 0\n" + kSquare),
                "declares 4 vertices and 1000000000 faces");
  // A face count near 2^64 (found by fuzzing): the needed size is said, not cast out of range.
  ExpectRefused(Write("huge.off", "OFF\n4 02953255926290448384 0.0 2"), "at least 10^18 bytes");
  ExpectRefused(Write("small.off", "OFF\n4 1 0\n" + kSquare + "2 0 1      \n"), "2 corners");
  ExpectRefused(Write("big.off", "OFF\n4 1 0\n" + kSquare + "1000 0 1 2\n"), "1000 corners");
  ExpectRefused(Write("xyz.off", "OFF\n4 1 0\n0 0 0\nx y z\n1 1 0\n0 1 0\n3 0 1 2\n"), "bad coordinate 'x'");
  ExpectRefused(Write("notoff.off", "PLY\n4 1 0\n"), "not an OFF file");
  ExpectRefused(Write("dim.off", "4OFF\n4 1 0\n"), "not supported");
}

TEST_F(MeshReaders, OffCommentsColorsAndCountsOnTheHeaderLineAreRead) {
  const auto r =
      Load(Write("c.off", "# made by hand\nCOFF 4 2 0\n# vertices\n0 0 0 255 0 0\n1 0 0 0 255 0\n"
                          "1 1 0 0 0 255\n0 1 0 1 1 1\n\n3 0 1 2 # a comment\n3 0 2 3 10 20 30\n"));
  ASSERT_TRUE(r->ok) << r->error;
  EXPECT_EQ(r->mesh.vn, 4);
  EXPECT_EQ(r->mesh.fn, 2);
}

// --- STL -----------------------------------------------------------------------------------------

const std::string kAsciiFacet = " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
                                "   vertex 0 1 0\n  endloop\n endfacet\n";

TEST_F(MeshReaders, StlWithoutTrailingNewlineIsReadWithoutLooping) {
  const auto r = Load(Write("nonl.stl", "solid t\n" + kAsciiFacet + "endsolid t"));
  ASSERT_TRUE(r->ok) << r->error;
  EXPECT_EQ(r->mesh.fn, 1);
  EXPECT_EQ(r->mesh.vn, 3);
  ExpectRefused(Write("cut.stl", "solid t\n" + kAsciiFacet.substr(0, 49)),
                "where 'vertex' was expected (truncated)");
}

TEST_F(MeshReaders, StlAsciiMissingEndloopEndfacetOrEndsolidIsRefused) {
  std::string noEndloop = kAsciiFacet;
  noEndloop.erase(noEndloop.find("  endloop\n"), 10);
  ExpectRefused(Write("noloop.stl", "solid t\n" + noEndloop + "endsolid t\n"), "expected 'endloop'");
  std::string noEndfacet = kAsciiFacet;
  noEndfacet.erase(noEndfacet.find(" endfacet\n"), 10);
  ExpectRefused(Write("nofacet.stl", "solid t\n" + noEndfacet + kAsciiFacet + "endsolid t\n"),
                "expected 'endfacet'");
  ExpectRefused(Write("nosolid.stl", "solid t\n" + kAsciiFacet + kAsciiFacet), "before 'endsolid'");
  ExpectRefused(Write("garbage.stl", "solid t\n" + kAsciiFacet + "facet normal 0 0 1x\n"), "bad number '1x'");
}

TEST_F(MeshReaders, StlBinaryWithAWrongFacetCountIsRefused) {
  std::string stl(80, ' ');
  auto facets = [&](std::uint32_t n) {
    std::string out = stl;
    out.append(reinterpret_cast<const char*>(&n), 4);
    for (std::uint32_t f = 0; f < 2; ++f) {
      const float data[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, float(f + 1), 0};
      out.append(reinterpret_cast<const char*>(data), sizeof data);
      out += std::string(2, '\0');
    }
    return out;
  };
  const auto two = Load(Write("two.stl", facets(2)));
  ASSERT_TRUE(two->ok) << two->error;
  EXPECT_EQ(two->mesh.fn, 2);
  EXPECT_EQ(two->mesh.vn, 4); // the shared edge's two vertices welded
  ExpectRefused(Write("three.stl", facets(3)), "declares 3 facets");
  ExpectRefused(Write("one.stl", facets(1)), "declares 1 facets");
  ExpectRefused(Write("tiny.stl", "abc"), "not a valid STL file");
}

// --- OBJ -----------------------------------------------------------------------------------------

TEST_F(MeshReaders, ObjIndicesMustBeWholeIntegersInRange) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
  ExpectRefused(Write("wrap.obj", v + "f 4294967297 2 3\n"), "'4294967297' is out of range");
  ExpectRefused(Write("frac.obj", v + "f 1.9 2 3\n"), "bad face corner '1.9' at line 5");
  ExpectRefused(Write("abc.obj", v + "f 1abc 2 3\n"), "bad face corner '1abc'");
  ExpectRefused(Write("zero.obj", v + "f 0 1 2\n"), "bad face corner '0'");
  ExpectRefused(Write("rel.obj", v + "f -5 1 2\n"), "out of range");
  ExpectRefused(Write("slash.obj", v + "f 1/x 2 3\n"), "bad face corner '1/x'");
  ExpectRefused(Write("vert.obj", "v 0 0 zero\n"), "bad vertex at line 1");
  ExpectRefused(Write("two.obj", v + "f 1 2\n"), "2 corners");
  ExpectRefused(Write("none.obj", "# nothing\n"), "no vertices found");
  const auto r =
      Load(Write("forms.obj", v + "vt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1\nf -4 -2 -1\ng x\nf 1 2 3 4\n"));
  ASSERT_TRUE(r->ok) << r->error;
  EXPECT_EQ(r->mesh.fn, 4);
  EXPECT_EQ(r->mesh.face[1].V(2), &r->mesh.vert[3]);
}

TEST_F(MeshReaders, ObjPolygonsBeyondTheCornerLimitAreRefused) {
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i < 5000; ++i) obj += " " + std::to_string(i % 3 + 1);
  ExpectRefused(Write("huge.obj", obj + "\n"), "corners (3 to 256 supported)");
}

// --- VRML (.wrl) ---------------------------------------------------------------------------------

/// A VRML 2.0 file shaped as PyMOL writes one: viewpoint and lights, then a Shape whose
/// IndexedFaceSet has its coordinates, polygons ended by -1, colors and normals.
std::string PymolStyleWrl(const std::string& points, const std::string& indices,
                          const std::string& extra = "") {
  return "#VRML V2.0 utf8\n\nViewpoint {\n position 0 0 119.7\n orientation 1 0 0 0\n description \"Z "
         "view\"\n}\n"
         "DirectionalLight {\n direction -0.34 -0.34 -0.87\n}\nShape {\n appearance Appearance {\n"
         "  material Material { diffuseColor 1.0 1.0 1.0 }\n }\n geometry IndexedFaceSet {\n" +
         extra + "  coord Coordinate {\n   point [\n" + points + "   ]\n  }\n  coordIndex [\n" + indices +
         "  ]\n  colorPerVertex TRUE\n  color Color {\n   color [\n1.0 0.3 0.3,\n1.0 0.3 0.3,\n  ] }\n"
         "  normal Normal { vector [ 0 0 1, 0 0 1 ] } # normals are recomputed\n  normalIndex [ 0 1 1 -1 ]\n "
         "}\n}\n";
}

const std::string kWrlSquare = "0 0 0,\n1 0 0,\n1 1 0,\n0 1 0,\n";

TEST_F(MeshReaders, WrlIndexedFaceSetsAreReadAsPymolWritesThem) {
  const auto r = Load(Write("pymol.wrl", PymolStyleWrl(kWrlSquare, "0 1 2 -1,\n0 2 3 -1,\n")));
  ASSERT_TRUE(r->ok) << r->error;
  EXPECT_EQ(r->mesh.vn, 4);
  ASSERT_EQ(r->mesh.fn, 2);
  EXPECT_EQ(r->mesh.face[1].V(2), &r->mesh.vert[3]);
  EXPECT_EQ(r->mesh.vert[2].P(), vcg::Point3d(1, 1, 0));
  // Two shapes: the second set's indices are its own; a quad is a fan; the last -1 is optional;
  // ccw FALSE reverses the polygons.
  const std::string two =
      PymolStyleWrl(kWrlSquare, "0 1 2 3") +
      "Shape { geometry DEF second IndexedFaceSet {\n"
      "ccw FALSE coord Coordinate { point [ 5 0 0, 6 0 0, 5 1 0 ] } coordIndex [ 0 1 2 -1 ] } }\n";
  const auto s = Load(Write("two.wrl", two));
  ASSERT_TRUE(s->ok) << s->error;
  EXPECT_EQ(s->mesh.vn, 7);
  ASSERT_EQ(s->mesh.fn, 3);
  EXPECT_EQ(s->mesh.face[2].V(0), &s->mesh.vert[6]);
  EXPECT_EQ(s->mesh.face[2].V(2), &s->mesh.vert[4]);
  // PyMOL draws a ligand's sticks as Cylinders in moving Transforms: skipped, the surface is read.
  const std::string sticks =
      "#VRML V2.0 utf8\nTransform {\n translation -1.2 -5.5 -5.7\n rotation 0.7 0 0.6 1.4\n"
      " children [ Shape { geometry Cylinder { radius 0.25 height 1.5 } } ]\n}\n";
  const auto t = Load(Write("sticks.wrl", sticks + PymolStyleWrl(kWrlSquare, "0 1 2 -1").substr(16)));
  ASSERT_TRUE(t->ok) << t->error;
  EXPECT_EQ(t->mesh.fn, 1);
}

TEST_F(MeshReaders, WrlFilesItCannotPlaceOrIndexAreRefused) {
  const std::string tri = "0 1 2 -1\n";
  ExpectRefused(Write("v1.wrl", "#VRML V1.0 ascii\nSeparator { }\n"), "VRML 1.0 is not supported");
  ExpectRefused(Write("plain.wrl", "Shape { }\n"), "not a VRML 2.0 file");
  ExpectRefused(Write("moved.wrl", "#VRML V2.0 utf8\nTransform { translation 1 0 0 children [\n" +
                                       PymolStyleWrl(kWrlSquare, tri).substr(16) + "] }\n"),
                "a Transform translation is not supported");
  ExpectRefused(
      Write("use.wrl",
            "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord USE c coordIndex [ 0 1 2 ] } }\n"),
      "shared with USE");
  ExpectRefused(Write("count.wrl", PymolStyleWrl("0 0 0, 1 0 0, 1 1\n", tri)),
                "8 numbers, not a multiple of 3");
  ExpectRefused(Write("range.wrl", PymolStyleWrl(kWrlSquare, "0 1 4 -1\n")), "coordIndex 4 is out of range");
  ExpectRefused(Write("minus.wrl", PymolStyleWrl(kWrlSquare, "0 1 -2 -1\n")),
                "coordIndex -2 is out of range");
  ExpectRefused(Write("frac.wrl", PymolStyleWrl(kWrlSquare, "0 1 2.5 -1\n")), "bad number '2.5'");
  ExpectRefused(Write("word.wrl", PymolStyleWrl("0 0 zero, 1 0 0, 1 1 0\n", tri)), "bad number 'zero'");
  ExpectRefused(Write("two.wrl", PymolStyleWrl(kWrlSquare, "0 1 -1\n")), "2 corners");
  ExpectRefused(
      Write("nocoord.wrl", "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coordIndex [ 0 1 2 ] } }\n"),
      "coordIndex but no coord");
  ExpectRefused(Write("none.wrl", "#VRML V2.0 utf8\nShape { geometry Sphere { radius 1 } }\n"),
                "no IndexedFaceSet found");
  const std::string whole = PymolStyleWrl(kWrlSquare, tri);
  ExpectRefused(Write("cut.wrl", whole.substr(0, whole.find("coordIndex") + 16)),
                "the file ends inside a list");
  ExpectRefused(Write("open.wrl", whole.substr(0, whole.size() - 3)), "unbalanced braces");
  ExpectRefused(Write("closer.wrl", whole + "]\n"), "unbalanced ']'");
}

// --- files that are not meshes -------------------------------------------------------------------

TEST_F(MeshReaders, DirectoriesFifosAndEmptyFilesAreRefusedByType) {
  std::filesystem::create_directories(dir_ / "folder.off");
  std::filesystem::create_directories(dir_ / "folder.stl");
  ExpectRefused((dir_ / "folder.off").string(), "is a directory");
  ExpectRefused((dir_ / "folder.stl").string(), "is a directory");
  const std::string fifo = (dir_ / "pipe.ply").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  ExpectRefused(fifo, "not a regular file");
  ExpectRefused(Write("empty.stl", ""), "the file is empty");
  ExpectRefused((dir_ / "missing.ply").string(), "no such file");
  ExpectRefused(Write("text.ply", "hello\n"), "not a PLY file");
  ExpectRefused(Write("ply.off", AsciiPly(4, 0, kSquare)), "not an OFF file");
  ExpectRefused(Write("ply.stl", BinaryPly({{0, 1, 2}})), "not a valid STL file");
}

TEST(NumberTokens, WholeTokensOnly) {
  double d = 0;
  float f = 0;
  long long i = 0;
  EXPECT_TRUE(molremesh::ParseDoubleToken("+1.5e3", d));
  EXPECT_EQ(d, 1500);
  EXPECT_FALSE(molremesh::ParseDoubleToken("1.5e3x", d));
  EXPECT_FALSE(molremesh::ParseDoubleToken("0x10", d));
  EXPECT_FALSE(molremesh::ParseDoubleToken("", d));
  EXPECT_FALSE(molremesh::ParseDoubleToken("+-1", d));
  EXPECT_TRUE(molremesh::ParseDoubleToken("nan", d)); // non-finite text is the cleaning stage's call
  EXPECT_TRUE(std::isnan(d));
  EXPECT_TRUE(molremesh::ParseFloatToken("1e39", f));
  EXPECT_TRUE(std::isinf(f));
  EXPECT_TRUE(molremesh::ParseFloatToken("1e-50", f));
  EXPECT_EQ(f, 0.0f);
  EXPECT_TRUE(molremesh::ParseFloatToken("0.1", f));
  EXPECT_EQ(f, 0.1f);
  EXPECT_FALSE(molremesh::ParseIntegerToken("1.0", i));
  EXPECT_FALSE(molremesh::ParseIntegerToken("99999999999999999999", i));
  EXPECT_TRUE(molremesh::ParseIntegerToken("-7", i));
  EXPECT_EQ(i, -7);
}

// --- the same mesh as vcglib's importers on valid files -------------------------------------------

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

/// vcglib's importer for path's format (and the STL weld LoadMesh applies).
bool LoadWithVcg(MeshD& m, const std::string& path) {
  int mask = 0;
  switch (molremesh::FormatFromPath(path)) {
  case molremesh::MeshFormat::Ply:
    return vcg::tri::io::ImporterPLY<MeshD>::Open(m, path.c_str(), mask) == 0;
  case molremesh::MeshFormat::Off:
    return vcg::tri::io::ImporterOFF<MeshD>::Open(m, path.c_str(), mask) == 0;
  case molremesh::MeshFormat::Stl:
    if (vcg::tri::io::ImporterSTL<MeshD>::Open(m, path.c_str(), mask) != 0) return false;
    vcg::tri::Clean<MeshD>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<MeshD>::CompactEveryVector(m);
    return true;
  default:
    return false;
  }
}

/// Same vertices (bit for bit, in order) and the same faces (vertex indices, in order).
void ExpectSameMesh(const MeshD& ours, const MeshD& theirs, const std::string& what) {
  ASSERT_EQ(ours.vn, theirs.vn) << what;
  ASSERT_EQ(ours.fn, theirs.fn) << what;
  for (std::size_t v = 0; v < ours.vert.size(); ++v)
    ASSERT_EQ(std::memcmp(&ours.vert[v].cP()[0], &theirs.vert[v].cP()[0], 3 * sizeof(double)), 0)
        << what << " vertex " << v;
  for (std::size_t f = 0; f < ours.face.size(); ++f)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(ours.face[f].cV(k) - &ours.vert[0], theirs.face[f].cV(k) - &theirs.vert[0])
          << what << " face " << f;
}

TEST_F(MeshReaders, SameMeshAsVcglibOnTheSharedMeshesAndTheirConversions) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  for (const auto& entry : std::filesystem::directory_iterator(SharedMesh(""))) {
    const std::string path = entry.path().string();
    if (molremesh::FormatFromPath(path) != molremesh::MeshFormat::Ply) continue;
    const auto ours = Load(path);
    ASSERT_TRUE(ours->ok) << ours->error;
    MeshD theirs;
    ASSERT_TRUE(LoadWithVcg(theirs, path)) << path;
    ExpectSameMesh(ours->mesh, theirs, path);
  }
  // The other formats and PLY ascii, through vcglib's exporters.
  const auto bpti = Load(SharedMesh("bpti_1bpi_msms.ply"));
  ASSERT_TRUE(bpti->ok) << bpti->error;
  for (const std::string name : {"a.ply", "b.ply", "c.off", "d.stl", "e.stl"}) {
    const std::string path = (dir_ / name).string();
    std::string error;
    const bool ascii = name[0] == 'a' || name[0] == 'e';
    ASSERT_TRUE(molremesh::SaveMesh(bpti->mesh, path, error, false, ascii)) << error;
    const auto ours = Load(path);
    ASSERT_TRUE(ours->ok) << ours->error;
    if (name == "d.stl" && kAddressSanitizer) continue; // vcglib's binary STL reader overreads its header
    MeshD theirs;
    ASSERT_TRUE(LoadWithVcg(theirs, path)) << path;
    ExpectSameMesh(ours->mesh, theirs, name);
  }
}

TEST_F(MeshReaders, SameMeshAsVcglibOnPolygonsQuadsAndStrips) {
  std::string off = "OFF\n# a bent quad grid and a pentagon\n36 26 0\n";
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      off += std::to_string(i + 0.1 * std::sin(j)) + " " + std::to_string(1.3 * j) + " " +
             std::to_string(0.3 * std::cos(i * j)) + "\n";
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const int a = 6 * i + j;
      off += "4 " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + 7) + " " +
             std::to_string(a + 6) + "\n";
    }
  off += "5 0 1 2 3 4\n";
  const std::string ply =
      AsciiPly(6, 2, "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 1.5 0.1\n-0.5 0.5 1e-3\n5 0 1 2 4 3\n4 0 3 5 0\n");
  const std::string strip = "ply\nformat ascii 1.0\nelement vertex 5\n" + kXyz +
                            "element tristrips 1\nproperty list int int vertex_indices\nend_header\n" +
                            kSquare + "2 2 2\n9 0 1 2 3 4 -1 3 2 4\n";
  for (const auto& [name, content] : std::vector<std::pair<std::string, std::string>>{
           {"grid.off", off}, {"poly.ply", ply}, {"strip.ply", strip}}) {
    const std::string path = Write(name, content);
    const auto ours = Load(path);
    ASSERT_TRUE(ours->ok) << ours->error;
    if (name == "strip.ply" && kAddressSanitizer) continue; // vcglib's strip reading leaks its list
    MeshD theirs;
    ASSERT_TRUE(LoadWithVcg(theirs, path)) << path;
    ExpectSameMesh(ours->mesh, theirs, name);
  }
}

} // namespace
