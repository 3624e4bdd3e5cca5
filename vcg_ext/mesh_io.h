// Reading and writing meshes for the CLI, tests and benchmarks (PLY ascii/binary, OFF, OBJ, STL).
//
// Thin layer over vcglib's importers/exporters that turns every failure into one clear message
// instead of an error code, and welds STL's per-face vertex copies so topology is meaningful.
// Requires vcglib's wrap/ply/plylib.cpp to be linked (target vcg_ply).
#pragma once

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/update/topology.h>
#include <wrap/io_trimesh/export_obj.h>
#include <wrap/io_trimesh/export_off.h>
#include <wrap/io_trimesh/export_ply.h>
#include <wrap/io_trimesh/export_stl.h>
#include <wrap/io_trimesh/import_off.h>
#include <wrap/io_trimesh/import_ply.h>
#include <wrap/io_trimesh/import_stl.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <sstream>
#include <vector>
#include <cctype>
#include <fstream>
#include <string>

namespace molremesh {

enum class MeshFormat { Unknown, Ply, Off, Obj, Stl };

/// Format from the file name's extension (case-insensitive).
inline MeshFormat FormatFromPath(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos) return MeshFormat::Unknown;
  std::string extension = path.substr(dot + 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (extension == "ply") return MeshFormat::Ply;
  if (extension == "off") return MeshFormat::Off;
  if (extension == "obj") return MeshFormat::Obj;
  if (extension == "stl") return MeshFormat::Stl;
  return MeshFormat::Unknown;
}

/// Reads the vertices and faces of a Wavefront OBJ file (polygons are fan-triangulated; texture
/// and normal indices, negative relative indices and everything else are handled or ignored).
/// Our own reader because vcglib 2020.09's ImporterOBJ miscounts faces on some files (it loses
/// triangles, asserting in debug builds).
template <class MeshType>
bool ReadObjTriangles(MeshType& m, const std::string& path, std::string& error) {
  using Scalar = typename MeshType::ScalarType;
  std::ifstream in(path);
  std::vector<vcg::Point3d> points;
  std::vector<std::array<int, 3>> triangles;
  std::string line;
  std::size_t lineNumber = 0;
  while (std::getline(in, line)) {
    ++lineNumber;
    std::istringstream tokens(line);
    std::string kind;
    if (!(tokens >> kind)) continue;
    if (kind == "v") {
      double x, y, z;
      if (!(tokens >> x >> y >> z)) {
        error = "bad vertex at line " + std::to_string(lineNumber);
        return false;
      }
      points.emplace_back(x, y, z);
    } else if (kind == "f") {
      std::vector<int> corners;
      std::string corner;
      while (tokens >> corner) {
        const int index = std::atoi(corner.substr(0, corner.find('/')).c_str());
        const int resolved = index > 0 ? index - 1 : int(points.size()) + index;
        if (index == 0 || resolved < 0) {
          error = "bad face index at line " + std::to_string(lineNumber);
          return false;
        }
        corners.push_back(resolved);
      }
      for (std::size_t k = 2; k < corners.size(); ++k) triangles.push_back({corners[0], corners[k - 1], corners[k]});
    }
  }
  if (points.empty()) {
    error = "no vertices found (not an OBJ file?)";
    return false;
  }
  for (const auto& t : triangles)
    for (int i : t)
      if (i >= int(points.size())) {
        error = "a face refers to vertex " + std::to_string(i + 1) + " of " + std::to_string(points.size());
        return false;
      }
  vcg::tri::Allocator<MeshType>::AddVertices(m, points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    m.vert[i].P() = vcg::Point3<Scalar>(Scalar(points[i][0]), Scalar(points[i][1]), Scalar(points[i][2]));
  vcg::tri::Allocator<MeshType>::AddFaces(m, triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) m.face[f].V(k) = &m.vert[std::size_t(triangles[f][k])];
  return true;
}

/// Loads path into m (cleared first). Returns true on success; otherwise error holds one line.
/// Only geometry and faces are read: colors, normals and texture coordinates are not needed by
/// molremesh and are recomputed where they are written.
template <class MeshType>
bool LoadMesh(MeshType& m, const std::string& path, std::string& error) {
  m.Clear();
  std::ifstream probe(path, std::ios::binary | std::ios::ate);
  if (!probe) {
    error = "cannot open '" + path + "': no such file or not readable";
    return false;
  }
  if (probe.tellg() == 0) {
    error = "cannot read '" + path + "': the file is empty";
    return false;
  }
  probe.close();

  int loadMask = 0;
  int code = 0;
  bool critical = false;
  const char* message = "";
  switch (FormatFromPath(path)) {
  case MeshFormat::Ply:
    code = vcg::tri::io::ImporterPLY<MeshType>::Open(m, path.c_str(), loadMask);
    critical = code != 0 && vcg::tri::io::ImporterPLY<MeshType>::ErrorCritical(code);
    message = vcg::tri::io::ImporterPLY<MeshType>::ErrorMsg(code);
    break;
  case MeshFormat::Off:
    code = vcg::tri::io::ImporterOFF<MeshType>::Open(m, path.c_str(), loadMask);
    critical = code != 0;
    message = vcg::tri::io::ImporterOFF<MeshType>::ErrorMsg(code);
    break;
  case MeshFormat::Obj: {
    std::string objError;
    if (!ReadObjTriangles(m, path, objError)) {
      m.Clear();
      error = "cannot read '" + path + "': " + objError;
      return false;
    }
    break;
  }
  case MeshFormat::Stl:
    code = vcg::tri::io::ImporterSTL<MeshType>::Open(m, path.c_str(), loadMask);
    critical = code != 0;
    message = vcg::tri::io::ImporterSTL<MeshType>::ErrorMsg(code);
    break;
  case MeshFormat::Unknown:
    error = "cannot read '" + path + "': unknown format (use .ply, .off, .obj or .stl)";
    return false;
  }
  if (critical) {
    m.Clear();
    error = "cannot read '" + path + "': " + message;
    return false;
  }
  if (FormatFromPath(path) == MeshFormat::Stl) {
    // STL stores three private vertices per triangle; weld exact copies only.
    vcg::tri::Clean<MeshType>::RemoveDuplicateVertex(m);
    vcg::tri::Allocator<MeshType>::CompactEveryVector(m);
  }
  return true;
}

/// Saves m to path; the format comes from the extension. PLY is written binary unless ascii is
/// set. withQualityAndColor adds per-vertex/per-face color and quality (must be enabled).
template <class MeshType>
bool SaveMesh(MeshType& m, const std::string& path, std::string& error, bool withQualityAndColor = false,
              bool ascii = false) {
  namespace io = vcg::tri::io;
  int mask = 0;
  if (withQualityAndColor)
    mask = io::Mask::IOM_VERTCOLOR | io::Mask::IOM_FACECOLOR | io::Mask::IOM_VERTQUALITY |
           io::Mask::IOM_FACEQUALITY;
  int code = 0;
  const char* message = "";
  switch (FormatFromPath(path)) {
  case MeshFormat::Ply:
    code = io::ExporterPLY<MeshType>::Save(m, path.c_str(), mask, !ascii);
    message = io::ExporterPLY<MeshType>::ErrorMsg(code);
    break;
  case MeshFormat::Off:
    code = io::ExporterOFF<MeshType>::Save(m, path.c_str(), mask & io::Mask::IOM_VERTCOLOR);
    message = io::ExporterOFF<MeshType>::ErrorMsg(code);
    break;
  case MeshFormat::Obj:
    code = io::ExporterOBJ<MeshType>::Save(m, path.c_str(), 0);
    message = io::ExporterOBJ<MeshType>::ErrorMsg(code);
    break;
  case MeshFormat::Stl:
    code = io::ExporterSTL<MeshType>::Save(m, path.c_str(), !ascii);
    message = io::ExporterSTL<MeshType>::ErrorMsg(code);
    break;
  case MeshFormat::Unknown:
    error = "cannot write '" + path + "': unknown format (use .ply, .off, .obj or .stl)";
    return false;
  }
  if (code != 0) {
    error = "cannot write '" + path + "': " + message;
    return false;
  }
  return true;
}

} // namespace molremesh
