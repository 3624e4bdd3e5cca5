// Reading and writing meshes for the CLI, tests and benchmarks (PLY ascii/binary, OFF, OBJ, STL;
// VRML 2.0 .wrl read only).
//
// Reading goes through our own validating readers (vcg_ext/io/*_reader.h), writing through
// vcglib's exporters; every failure is one clear message instead of an error code, and STL's
// per-face vertex copies are welded so topology is meaningful. Requires vcglib's
// wrap/ply/plylib.cpp to be linked for writing PLY (target vcg_ply).
#pragma once

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/update/topology.h>
#include <wrap/io_trimesh/export_obj.h>
#include <wrap/io_trimesh/export_off.h>
#include <wrap/io_trimesh/export_ply.h>
#include <wrap/io_trimesh/export_stl.h>
#include <vcg_ext/io/obj_reader.h>
#include <vcg_ext/io/off_reader.h>
#include <vcg_ext/io/ply_reader.h>
#include <vcg_ext/io/stl_reader.h>
#include <vcg_ext/io/wrl_reader.h>

#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>

namespace molremesh {

enum class MeshFormat { Unknown, Ply, Off, Obj, Stl, Wrl };

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
  if (extension == "wrl") return MeshFormat::Wrl;
  return MeshFormat::Unknown;
}

/// The message for a file name whose extension names no format molremesh reads.
constexpr const char* kReadableFormats = "unknown format (use .ply, .off, .obj, .stl or .wrl)";

/// Parses bytes of the given format into raw (no file access: the fuzz targets call this too).
inline bool ReadRawMesh(std::string_view bytes, MeshFormat format, RawMesh& raw, std::string& error) {
  switch (format) {
  case MeshFormat::Ply:
    return PlyReader::Read(bytes, raw, error);
  case MeshFormat::Off:
    return OffReader::Read(bytes, raw, error);
  case MeshFormat::Obj:
    return ObjReader::Read(bytes, raw, error);
  case MeshFormat::Stl:
    return StlReader::Read(bytes, raw, error);
  case MeshFormat::Wrl:
    return WrlReader::Read(bytes, raw, error);
  case MeshFormat::Unknown:
    break;
  }
  error = kReadableFormats;
  return false;
}

/// Loads path into m (cleared first). Returns true on success; otherwise m is empty and error
/// holds one line naming the file and what is wrong. Only geometry and faces are read: colors,
/// normals and texture coordinates are not needed by molremesh and are recomputed where written.
/// Our own readers (vcg_ext/io/*_reader.h) instead of vcglib's importers, which trust counts and
/// indices (crashes, hangs and silent garbage on hostile files); on valid files they give the
/// same vertices and faces in the same order.
template <class MeshType>
bool LoadMesh(MeshType& m, const std::string& path, std::string& error) {
  m.Clear();
  const MeshFormat format = FormatFromPath(path);
  std::string bytes;
  RawMesh raw;
  std::string why;
  if (format == MeshFormat::Unknown) {
    why = kReadableFormats;
  } else if (ReadRegularFile(path, bytes, why) && ReadRawMesh(bytes, format, raw, why)) {
    bytes = std::string();
    BuildMeshFromRaw(m, raw);
    if (format == MeshFormat::Stl) {
      // STL stores three private vertices per triangle; weld exact copies only.
      vcg::tri::Clean<MeshType>::RemoveDuplicateVertex(m);
      vcg::tri::Allocator<MeshType>::CompactEveryVector(m);
    }
    return true;
  }
  error = "cannot read '" + path + "': " + why;
  return false;
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
  case MeshFormat::Wrl:
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
