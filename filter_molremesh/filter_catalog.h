// The molremesh filters described once, for every MeshLab plugin interface: their ids, names,
// descriptions, parameters (name, type, default, label, help), and the reading of parameter values
// into vcg_ext Params. No MeshLab or Qt header here: the adapters (meshlab2020/, meshlab2023/) turn
// these descriptions into their interface's RichParameters and call the run functions of
// filter_runs.h.
#pragma once

// The mesh types (and with them vcglib's complex.h) before the pipeline, whose vcglib headers
// expect complex.h included first.
#include <vcg_ext/core/mesh_types.h>

#include <vcg_ext/pipeline/remesh_pipeline.h>

#include <map>
#include <string>
#include <vector>

namespace molremesh::filters {

/// The filters, in menu order; the values are the MeshLab filter ids of both adapters.
enum class FilterId {
  QualityReport,
  ColorBadElements,
  CleanRawMesh,
  CvtInitialization,
  RandomSegmentation,
  PatchwiseRar,
  ValenceOptimization,
  RemoveSmallAngles,
  ReduceObtuse,
  LocalSmoothing,
  FullPipeline,
  SurfaceFromStructure,
};

/// What a filter does to the layer, which decides its menu, its attributes and how it runs.
enum class FilterKind {
  Measure,      ///< reads the mesh only (Quality Report)
  Coloring,     ///< writes colors and qualities (Color Bad Elements)
  Segmentation, ///< writes face colors and a per-face attribute (Random Segmentation)
  Stages,       ///< runs pipeline stages and replaces the mesh (or adds a layer)
  Creation,     ///< builds a new layer from a file, without an input layer (Surface from Structure File)
};

struct FilterSpec {
  FilterId id;
  std::string name; ///< menu name ("Molecular Remesh: ..."); PyMeshLab's name is derived from it
  std::string info; ///< description (rich text)
  FilterKind kind;
  std::vector<PipelineStage> stages; ///< the stages run (kind Stages)
  std::string layerSuffix;           ///< the new layer is "<input name> <suffix>" (kind Stages)
};

/// A parameter. Length: an edge length in the mesh's units, shown as absolute/percentage of the
/// bounding-box diagonal, its default the layer's mean edge length (filled in by the adapter).
/// Enum: one of `choices`, its value the index. File: a file to open, its value a path (no default),
/// offered with the name patterns `choices` ("*.pdb").
struct ParameterSpec {
  enum class Type { Bool, Int, Float, Length, Enum, File };
  Type type;
  std::string name;
  double defaultValue; ///< bools 0/1, enums the index; ignored for Length and File
  std::string label;
  std::string help;                      ///< MeshLab's tooltip and PyMeshLab's doc string
  bool needsFaceSelection = false;       ///< offered only on a layer with selected faces
  std::vector<std::string> choices = {}; ///< Enum: the choices' labels; File: the name patterns
};

/// Every filter, in menu order.
const std::vector<FilterSpec>& Filters();
const FilterSpec& Filter(FilterId id);
/// The parameters of a filter, in dialog order.
std::vector<ParameterSpec> Parameters(FilterId id);

/// The default of a Length parameter and its range (0 to the diagonal) for a layer, from its mean
/// edge length and bounding-box diagonal (either may be non-finite on a broken mesh).
struct LengthRange {
  double value = 0;
  double max = 1;
};
LengthRange LengthRangeOf(double meanEdgeLength, double diagonal);

/// The values of a run's parameters (bools 0/1, enums their index, files their path), read from
/// the host's parameter list.
class ParameterValues {
public:
  void Set(const std::string& name, double value) { values_[name] = value; }
  void SetText(const std::string& name, const std::string& text) { texts_[name] = text; }
  bool Has(const std::string& name) const { return values_.count(name) != 0 || texts_.count(name) != 0; }
  double Float(const std::string& name) const { return values_.at(name); }
  int Int(const std::string& name) const { return int(values_.at(name)); }
  bool Bool(const std::string& name) const { return values_.at(name) != 0; }
  const std::string& Text(const std::string& name) const { return texts_.at(name); }

private:
  std::map<std::string, double> values_;
  std::map<std::string, std::string> texts_;
};

/// The double a user meant by a float parameter (both MeshLab versions store them as float): its
/// shortest decimal, so 1.4f (1.39999997...) is the probe radius 1.4 the CLI uses and the plugin
/// computes what `molremesh` computes.
double DecimalOf(float value);

using Pipeline = RemeshPipeline<MeshD>;

/// Reads the parameters a stage filter declares into the pipeline's Params; "" or why they are
/// invalid (the message shown to the user).
std::string ReadStageParameters(const ParameterValues& values, Pipeline::Params& params);

} // namespace molremesh::filters
