// The MeshLab plugin loaded in-process the way MeshLab loads it (QPluginLoader), with filters
// applied to MeshDocument layers: refused inputs leave the layer bit-for-bit unchanged, and the
// coloring agrees with the quality report computed by vcg_ext on the same data.
#include <gtest/gtest.h>

#include <QApplication>
#include <QPluginLoader>

#include <set>
#include <utility>
#include <vector>

#include <common/GLLogStream.h>
#include <common/interfaces.h>
#include <common/meshmodel.h>
#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/append.h>
#include <wrap/io_trimesh/import_ply.h>

#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/quality/mesh_quality.h>

#include "test_helpers.h"

using namespace molremesh::test;

namespace {

MeshFilterInterface* LoadPlugin() {
  static QPluginLoader loader(MOLREMESH_PLUGIN_PATH);
  static MeshFilterInterface* plugin = qobject_cast<MeshFilterInterface*>(loader.instance());
  if (plugin == nullptr) ADD_FAILURE() << "cannot load plugin: " << loader.errorString().toStdString();
  return plugin;
}

QAction* FindFilter(MeshFilterInterface* plugin, const QString& name) {
  for (QAction* a : plugin->actions())
    if (a->text() == name) return a;
  ADD_FAILURE() << "no filter named " << name.toStdString();
  return nullptr;
}

/// Everything a filter could change on a layer.
struct LayerSnapshot {
  int vn = 0, fn = 0, dataMask = 0;
  std::vector<float> coords;
  std::vector<int> faceIndices, vertexFlags, faceFlags;
  std::vector<unsigned char> vertexColors;

  static LayerSnapshot Of(MeshModel& mm) {
    LayerSnapshot s;
    s.vn = mm.cm.vn;
    s.fn = mm.cm.fn;
    s.dataMask = mm.dataMask();
    for (auto& v : mm.cm.vert) {
      for (int k = 0; k < 3; ++k) s.coords.push_back(v.P()[k]);
      s.vertexFlags.push_back(v.Flags());
      for (int k = 0; k < 4; ++k) s.vertexColors.push_back(v.C()[k]);
    }
    for (auto& f : mm.cm.face) {
      for (int k = 0; k < 3; ++k) s.faceIndices.push_back(int(vcg::tri::Index(mm.cm, f.V(k))));
      s.faceFlags.push_back(f.Flags());
    }
    return s;
  }
  bool operator==(const LayerSnapshot& o) const {
    // NaN != NaN, so compare coordinates by bits.
    return vn == o.vn && fn == o.fn && dataMask == o.dataMask && coords.size() == o.coords.size() &&
           std::memcmp(coords.data(), o.coords.data(), coords.size() * sizeof(float)) == 0 &&
           faceIndices == o.faceIndices && vertexFlags == o.vertexFlags && faceFlags == o.faceFlags &&
           vertexColors == o.vertexColors;
  }
};

class PluginTest : public ::testing::Test {
protected:
  void SetUp() override {
    plugin = LoadPlugin();
    ASSERT_NE(plugin, nullptr);
    log.Clear();
    plugin->setLog(&log);
  }

  MeshModel* AddLayer(const std::string& path) {
    MeshModel* mm = document.addNewMesh(QString::fromStdString(path), "layer");
    if (!path.empty()) {
      int mask = 0;
      const int err = vcg::tri::io::ImporterPLY<CMeshO>::Open(mm->cm, path.c_str(), mask);
      EXPECT_FALSE(err != 0 && vcg::tri::io::ImporterPLY<CMeshO>::ErrorCritical(err)) << path;
    }
    return mm;
  }

  /// Runs the filter with its default parameters but the given float ones.
  bool Apply(const QString& filterName, MeshModel& mm,
             const std::vector<std::pair<QString, float>>& floats = {}) {
    QAction* action = FindFilter(plugin, filterName);
    if (action == nullptr) return false;
    RichParameterList parameters;
    plugin->initParameterSet(action, mm, parameters);
    for (const auto& [name, value] : floats) parameters.setValue(name, FloatValue(value));
    return plugin->applyFilter(action, document, parameters, nullptr);
  }

  std::string LogText() const {
    QStringList lines;
    log.print(lines);
    return lines.join("\n").toStdString();
  }

  MeshFilterInterface* plugin = nullptr;
  MeshDocument document;
  GLLogStream log;
};

const QString kReport = "Molecular Remesh: Quality Report";
const QString kColor = "Molecular Remesh: Color Bad Elements";
const QString kClean = "Molecular Remesh: Clean Raw Mesh";
const QString kCvt = "Molecular Remesh: CVT Initialization";
const QString kSegment = "Molecular Remesh: Random Segmentation";
const QString kRar = "Molecular Remesh: Patch-wise Adaptive Remeshing";
const QString kValence = "Molecular Remesh: Valence Optimization";
const QString kSmall = "Molecular Remesh: Remove Small Angles";
const QString kObtuse = "Molecular Remesh: Reduce Obtuse Triangles";
const QString kSmooth = "Molecular Remesh: Local Smoothing";
const QString kFull = "Molecular Remesh: Full Pipeline";
const QList<QString> kAllFilters = {kReport,  kColor, kClean,  kCvt,    kSegment, kRar,
                                    kValence, kSmall, kObtuse, kSmooth, kFull};

} // namespace

TEST_F(PluginTest, ExposesItsFiltersInTheRemeshingClass) {
  for (const QString& name : kAllFilters) {
    QAction* action = FindFilter(plugin, name);
    ASSERT_NE(action, nullptr);
    EXPECT_TRUE(plugin->getClass(action) & MeshFilterInterface::Remeshing);
    EXPECT_FALSE(plugin->filterInfo(action).isEmpty());
  }
}

struct BadInputCase {
  const char* fixture; ///< file under tests/data, or "" for an empty layer
  const char* expectedMessage;
};

class PluginBadInput : public PluginTest, public ::testing::WithParamInterface<BadInputCase> {};

TEST_P(PluginBadInput, EveryFilterRefusesAndLeavesTheLayerUntouched) {
  const BadInputCase c = GetParam();
  for (const QString& name : kAllFilters) {
    MeshModel* mm = AddLayer(*c.fixture ? Fixture(c.fixture) : std::string());
    const LayerSnapshot before = LayerSnapshot::Of(*mm);
    EXPECT_FALSE(Apply(name, *mm)) << name.toStdString();
    EXPECT_NE(plugin->errorMsg().toStdString().find(c.expectedMessage), std::string::npos)
        << plugin->errorMsg().toStdString();
    EXPECT_NE(LogText().find(c.expectedMessage), std::string::npos) << "the reason is logged too";
    EXPECT_TRUE(LayerSnapshot::Of(*mm) == before) << name.toStdString();
    document.delMesh(mm);
  }
}

INSTANTIATE_TEST_SUITE_P(Inputs, PluginBadInput,
                         ::testing::Values(BadInputCase{"", "empty"},
                                           BadInputCase{"point_cloud.ply", "point cloud"},
                                           BadInputCase{"nan_vertex.ply", "NaN"}),
                         [](const auto& testParam) {
                           const std::string file = testParam.param.fixture;
                           return file.empty() ? std::string("empty_layer") : file.substr(0, file.find('.'));
                         });

TEST_F(PluginTest, ReportOnNonManifoldAndDegenerateInputChangesNothing) {
  for (const char* fixture : {"nonmanifold_fan.ply", "degenerate_faces.ply"}) {
    MeshModel* mm = AddLayer(Fixture(fixture));
    const LayerSnapshot before = LayerSnapshot::Of(*mm);
    EXPECT_TRUE(Apply(kReport, *mm)) << fixture;
    EXPECT_TRUE(LayerSnapshot::Of(*mm) == before) << fixture;
    document.delMesh(mm);
  }
  EXPECT_NE(LogText().find("non-manifold edges"), std::string::npos);
}

TEST_F(PluginTest, ReportLogsTheTableOfARealMesh) {
  MOLREMESH_SKIP_WITHOUT_MESH("ubiquitin_1UBQ_edtsurf_mc.ply");
  MeshModel* mm = AddLayer(RealMesh("ubiquitin_1UBQ_edtsurf_mc.ply"));
  const LayerSnapshot before = LayerSnapshot::Of(*mm);
  ASSERT_TRUE(Apply(kReport, *mm)) << plugin->errorMsg().toStdString();
  EXPECT_TRUE(LayerSnapshot::Of(*mm) == before);
  const molremesh::QualityReport expected = molremesh::MeshQuality<CMeshO>::Compute(mm->cm);
  const std::string text = LogText();
  for (const char* row : {"Qmin", "V567", "obtuse faces", "genus", "self-intersecting pairs"})
    EXPECT_NE(text.find(row), std::string::npos) << row;
  EXPECT_NE(text.find(std::to_string(expected.boundaryEdges)), std::string::npos);
}

TEST_F(PluginTest, ColoringAgreesWithTheQualityReport) {
  MOLREMESH_SKIP_WITHOUT_MESH("ubiquitin_1UBQ_edtsurf_mc.ply");
  MOLREMESH_SKIP_WITHOUT_MESH("lysozyme_Lys1_msms.ply");
  for (const std::string& path :
       {RealMesh("ubiquitin_1UBQ_edtsurf_mc.ply"), RealMesh("lysozyme_Lys1_msms.ply"),
        Fixture("nonmanifold_fan.ply"), Fixture("degenerate_faces.ply")}) {
    MeshModel* mm = AddLayer(path);
    ASSERT_TRUE(Apply(kColor, *mm)) << plugin->errorMsg().toStdString();
    EXPECT_TRUE(mm->hasDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR |
                                MeshModel::MM_VERTQUALITY | MeshModel::MM_FACEQUALITY));
    const molremesh::QualityReport report = molremesh::MeshQuality<CMeshO>::Compute(mm->cm);
    using Coloring = molremesh::BadElementColoring<CMeshO>;
    std::size_t red = 0, blue = 0, magenta = 0, redVertices = 0;
    for (auto& f : mm->cm.face) {
      if (f.C() == Coloring::ObtuseFaceColor()) ++red;
      if (f.C() == Coloring::SmallAngleFaceColor()) ++blue;
      if (f.C() == Coloring::ObtuseAndSmallFaceColor()) ++magenta;
      EXPECT_NEAR(f.Q(), molremesh::MeshQuality<CMeshO>::FaceAngles(f).min(), 1e-3);
    }
    const std::vector<int> valence = molremesh::MeshQuality<CMeshO>::VertexValences(mm->cm);
    for (std::size_t i = 0; i < mm->cm.vert.size(); ++i) {
      if (mm->cm.vert[i].C() == Coloring::IrregularVertexColor()) ++redVertices;
      EXPECT_EQ(mm->cm.vert[i].Q(), float(valence[i]));
    }
    EXPECT_EQ(red + magenta, report.obtuseFaces) << path;
    EXPECT_EQ(blue + magenta, report.smallAngleFaces) << path;
    EXPECT_EQ(redVertices, report.interiorVertices - report.regularVertices) << path;
    document.delMesh(mm);
  }
}

TEST_F(PluginTest, CleanMakesANonManifoldLayerManifold) {
  MeshModel* mm = AddLayer(Fixture("nonmanifold_fan.ply"));
  ASSERT_TRUE(Apply(kClean, *mm)) << plugin->errorMsg().toStdString();
  const molremesh::QualityReport after = molremesh::MeshQuality<CMeshO>::Compute(mm->cm);
  EXPECT_GT(after.faces, 0u);
  EXPECT_EQ(after.nonManifoldEdges, 0u);
  EXPECT_EQ(after.nonManifoldVertices, 0u);
  EXPECT_EQ(after.degenerateFaces, 0u);
  EXPECT_NE(LogText().find("removed non-manifold faces"), std::string::npos) << LogText();
  document.delMesh(mm);
}

TEST_F(PluginTest, CleanClosesTheCracksOfARealMarchingCubesMesh) {
  MOLREMESH_SKIP_WITHOUT_MESH("ubiquitin_1UBQ_edtsurf_mc.ply");
  MeshModel* mm = AddLayer(RealMesh("ubiquitin_1UBQ_edtsurf_mc.ply"));
  ASSERT_TRUE(Apply(kClean, *mm)) << plugin->errorMsg().toStdString();
  const molremesh::QualityReport after = molremesh::MeshQuality<CMeshO>::Compute(mm->cm);
  EXPECT_EQ(after.boundaryEdges, 0u);
  EXPECT_TRUE(after.isTwoManifold());
  EXPECT_EQ(after.selfIntersectingPairs, 0u);
  EXPECT_GE(after.genus, 0);
  document.delMesh(mm);
}

TEST_F(PluginTest, CvtRefusesANonManifoldLayerAndLeavesItUntouched) {
  MeshModel* mm = AddLayer(Fixture("nonmanifold_fan.ply"));
  const LayerSnapshot before = LayerSnapshot::Of(*mm);
  EXPECT_FALSE(Apply(kCvt, *mm));
  EXPECT_FALSE(plugin->errorMsg().isEmpty());
  EXPECT_TRUE(LayerSnapshot::Of(*mm) == before);
  document.delMesh(mm);
}

TEST_F(PluginTest, StageFiltersRefuseANonManifoldLayerAndLeaveItUntouched) {
  for (const QString& name : {kValence, kSmall, kObtuse, kSmooth}) {
    MeshModel* mm = AddLayer(Fixture("nonmanifold_fan.ply"));
    const LayerSnapshot before = LayerSnapshot::Of(*mm);
    EXPECT_FALSE(Apply(name, *mm)) << name.toStdString();
    EXPECT_FALSE(plugin->errorMsg().isEmpty()) << name.toStdString();
    EXPECT_TRUE(LayerSnapshot::Of(*mm) == before) << name.toStdString();
    document.delMesh(mm);
  }
}

TEST_F(PluginTest, FullPipelineGivesEveryAngleWithinTheBoundsAndRegularVertices) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshModel* mm = AddLayer(SharedMesh("bpti_1bpi_msms.ply"));
  ASSERT_TRUE(Apply(kFull, *mm)) << plugin->errorMsg().toStdString();
  const molremesh::QualityReport after = molremesh::MeshQuality<CMeshO>::Compute(mm->cm);
  EXPECT_GE(after.angleMin, 30.0);
  EXPECT_LE(after.angleMax, 120.0);
  EXPECT_GE(after.v567Percent, 99.8);
  EXPECT_TRUE(after.isTwoManifold());
  EXPECT_EQ(after.boundaryEdges, 0u);
  EXPECT_EQ(after.selfIntersectingPairs, 0u);
  EXPECT_NE(LogText().find("stage times (s):"), std::string::npos) << "each stage's time is logged";
  EXPECT_NE(LogText().find("polish"), std::string::npos);
  EXPECT_EQ(LogText().find("Warning"), std::string::npos) << "every promise kept: no warning";
  document.delMesh(mm);
}

// Two interpenetrating closed spheres: a tangle no refill repairs, so the result keeps
// intersecting pairs. The layer takes the result, but the log says it is not valid, and why.
TEST_F(PluginTest, FullPipelineWarnsWhenTheResultIsNotValid) {
  MeshModel* mm = AddLayer("");
  CMeshO second;
  vcg::tri::Sphere(mm->cm, 3);
  vcg::tri::Sphere(second, 3);
  for (auto& v : second.vert) v.P() += CMeshO::CoordType(1.0f, 0.13f, 0.07f);
  vcg::tri::Append<CMeshO, CMeshO>::Mesh(mm->cm, second);
  ASSERT_TRUE(Apply(kFull, *mm)) << plugin->errorMsg().toStdString();
  const std::string text = LogText();
  EXPECT_NE(text.find("Warning: the result is not valid:"), std::string::npos) << text;
  EXPECT_NE(text.find("self-intersecting face pairs"), std::string::npos) << text;
  EXPECT_NE(text.find("tangle"), std::string::npos) << text;
  document.delMesh(mm);
}

// A target edge length 10^4 times below the layer's mean edge would make about 10^10 faces: the
// resampling filters refuse before they start (a run that outgrows the memory would take MeshLab
// down with it), the layer untouched; a memory limit of 1 MB refuses even the real run, and -1
// turns the check off.
TEST_F(PluginTest, ResamplingFiltersRefuseARunBeyondTheMemoryLimit) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  for (const QString& name : {kCvt, kRar, kFull}) {
    MeshModel* mm = AddLayer(SharedMesh("galactose_grasp.ply"));
    const LayerSnapshot before = LayerSnapshot::Of(*mm);
    EXPECT_FALSE(Apply(name, *mm, {{"targetLength", 0.0001f}})) << name.toStdString();
    const std::string error = plugin->errorMsg().toStdString();
    EXPECT_NE(error.find("refused: the run would need about"), std::string::npos) << error;
    EXPECT_NE(error.find("MB of memory available"), std::string::npos) << error;
    EXPECT_TRUE(LayerSnapshot::Of(*mm) == before) << name.toStdString();
    EXPECT_FALSE(Apply(name, *mm, {{"memoryLimit", 1.0f}})) << name.toStdString();
    EXPECT_NE(plugin->errorMsg().toStdString().find("1 MB memory limit"), std::string::npos);
    EXPECT_TRUE(LayerSnapshot::Of(*mm) == before) << name.toStdString();
    document.delMesh(mm);
  }
  MeshModel* mm = AddLayer(SharedMesh("galactose_grasp.ply"));
  EXPECT_TRUE(Apply(kCvt, *mm, {{"memoryLimit", -1.0f}})) << plugin->errorMsg().toStdString();
  document.delMesh(mm);
}

TEST_F(PluginTest, SegmentationColorsPatchesAndStoresTheirIds) {
  MOLREMESH_SKIP_WITHOUT_MESH("lysozyme_Lys1_msms.ply");
  MeshModel* mm = AddLayer(RealMesh("lysozyme_Lys1_msms.ply"));
  const LayerSnapshot before = LayerSnapshot::Of(*mm);
  ASSERT_TRUE(Apply(kSegment, *mm)) << plugin->errorMsg().toStdString();
  EXPECT_EQ(before.coords, LayerSnapshot::Of(*mm).coords) << "segmentation must not move vertices";
  EXPECT_TRUE(mm->hasDataMask(MeshModel::MM_FACECOLOR));
  ASSERT_TRUE(vcg::tri::HasPerFaceAttribute(mm->cm, "molremesh_patch"));
  auto patch = vcg::tri::Allocator<CMeshO>::GetPerFaceAttribute<int>(mm->cm, "molremesh_patch");
  std::set<int> ids;
  for (std::size_t i = 0; i < mm->cm.face.size(); ++i) ids.insert(patch[i]);
  EXPECT_GE(ids.size(), 2u);
  EXPECT_EQ(ids.count(-1), 0u);
  document.delMesh(mm);
}

int main(int argc, char** argv) {
  // QAction needs a QApplication; the offscreen platform needs no X display.
  qputenv("QT_QPA_PLATFORM", "offscreen");
  QApplication app(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
