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
      for (std::size_t k = 2; k < corners.size(); ++k)
        triangles.push_back({corners[0], corners[k - 1], corners[k]});
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

/// The smallest number of bytes the elements a PLY or OFF header declares can take, and the
/// counts; the importers allocate every declared element before reading one, so a header that
/// declares more than the file can hold (truncated, corrupt, hand-edited) would make them try to
/// allocate gigabytes. 0 bytes when the header cannot be read (the importer then says why).
struct DeclaredSize {
  double vertices = 0, faces = 0;
  double headerBytes = 0, minBodyBytes = 0;
};

inline DeclaredSize PlyDeclaredSize(const std::string& path) {
  DeclaredSize d;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  bool ascii = false;
  double count = 0;           // of the current element
  double minBytesPerItem = 0; // of the current element
  double* countTarget = nullptr;
  auto closeElement = [&]() {
    d.minBodyBytes += count * minBytesPerItem;
    if (countTarget) *countTarget = count;
  };
  auto scalarBytes = [&](const std::string& type) -> double {
    if (ascii) return 2; // a digit and a separator
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "double" || type == "float64") return 8;
    return 4;
  };
  for (int lines = 0; lines < 10000 && std::getline(in, line); ++lines) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "format") {
      std::string kind;
      words >> kind;
      ascii = kind == "ascii";
    } else if (keyword == "element") {
      closeElement();
      std::string name;
      words >> name >> count;
      minBytesPerItem = 0;
      countTarget = name == "vertex" ? &d.vertices : name == "face" ? &d.faces : nullptr;
    } else if (keyword == "property") {
      std::string type, countType, itemType;
      words >> type;
      if (type == "list") {
        words >> countType >> itemType;
        // A face lists at least three vertices; other lists may be empty.
        minBytesPerItem += scalarBytes(countType) + (countTarget == &d.faces ? 3 * scalarBytes(itemType) : 0);
      } else {
        minBytesPerItem += scalarBytes(type);
      }
    } else if (keyword == "end_header") {
      closeElement();
      d.headerBytes = double(in.tellg());
      return d;
    }
  }
  return DeclaredSize(); // no end_header: not a PLY header the check understands
}

inline DeclaredSize OffDeclaredSize(const std::string& path) {
  DeclaredSize d;
  std::ifstream in(path);
  std::string line;
  bool sawKeyword = false;
  for (int lines = 0; lines < 1000 && std::getline(in, line); ++lines) {
    const std::size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    std::istringstream words(line.substr(start));
    if (!sawKeyword && std::isalpha(static_cast<unsigned char>(line[start]))) {
      std::string keyword;
      words >> keyword;
      sawKeyword = true;
      if (keyword.find("OFF") == std::string::npos) return DeclaredSize();
      if (!(words >> d.vertices >> d.faces)) continue; // counts on the next line
    } else if (!(words >> d.vertices >> d.faces)) {
      return DeclaredSize();
    }
    d.headerBytes = double(in.tellg());
    // "x y z" per vertex, "3 a b c" per face: at least 2 bytes per number.
    d.minBodyBytes = 6 * d.vertices + 8 * d.faces;
    return d;
  }
  return DeclaredSize();
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
  const double fileBytes = double(probe.tellg());
  if (fileBytes == 0) {
    error = "cannot read '" + path + "': the file is empty";
    return false;
  }
  probe.close();
  const MeshFormat format = FormatFromPath(path);
  if (format == MeshFormat::Ply || format == MeshFormat::Off) {
    const DeclaredSize declared = format == MeshFormat::Ply ? PlyDeclaredSize(path) : OffDeclaredSize(path);
    // (- 1: the last line of an ASCII file may lack its newline.)
    if (declared.headerBytes > 0 && declared.headerBytes + declared.minBodyBytes - 1 > fileBytes) {
      std::ostringstream why;
      why.setf(std::ios::fixed);
      why.precision(0);
      why << "cannot read '" << path << "': its header declares " << declared.vertices << " vertices and "
          << declared.faces << " faces, at least " << declared.headerBytes + declared.minBodyBytes
          << " bytes, but the file has " << fileBytes << " (truncated or corrupt)";
      error = why.str();
      return false;
    }
  }

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
