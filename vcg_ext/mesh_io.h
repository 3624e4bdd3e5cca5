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
#include <wrap/io_trimesh/import_obj.h>
#include <wrap/io_trimesh/import_off.h>
#include <wrap/io_trimesh/import_ply.h>
#include <wrap/io_trimesh/import_stl.h>

#include <algorithm>
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
  case MeshFormat::Obj:
    code = vcg::tri::io::ImporterOBJ<MeshType>::Open(m, path.c_str(), loadMask);
    critical = code != 0 && vcg::tri::io::ImporterOBJ<MeshType>::ErrorCritical(code);
    message = vcg::tri::io::ImporterOBJ<MeshType>::ErrorMsg(code);
    break;
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
