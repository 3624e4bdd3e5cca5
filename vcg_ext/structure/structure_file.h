// Reads a structure file by its extension: PQR (radii from the file), PDB (freesasa, radii by its
// classifier), mmCIF (gemmi's CIF parser, radii by freesasa's classifier), each optionally
// gzip-compressed (.gz: decompressed to memory with zlib).
#pragma once

#include <vcg_ext/structure/atoms.h>
#include <vcg_ext/structure/mmcif_reader.h>
#include <vcg_ext/structure/pdb_reader.h>
#include <vcg_ext/structure/pqr_reader.h>

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <string>

namespace molremesh {

/// The format a structure file name says (after a trailing ".gz").
enum class StructureFormat { Unknown, Pqr, Pdb, MmCif };

inline std::string LowerExtension(std::string path, bool& gzipped) {
  std::transform(path.begin(), path.end(), path.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  gzipped = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  if (gzipped) path.resize(path.size() - 3);
  const auto dot = path.find_last_of('.'), slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return path.substr(dot + 1);
}

inline StructureFormat StructureFormatFromPath(const std::string& path) {
  bool gzipped = false;
  const std::string ext = LowerExtension(path, gzipped);
  if (ext == "pqr") return StructureFormat::Pqr;
  if (ext == "pdb" || ext == "ent") return StructureFormat::Pdb;
  if (ext == "cif" || ext == "mmcif") return StructureFormat::MmCif;
  return StructureFormat::Unknown;
}

/// gzip data (one or more members) decompressed, or false with `error` set.
inline bool Gunzip(const std::string& compressed, std::string& text, std::string& error) {
  z_stream z{};
  if (inflateInit2(&z, 15 + 32) != Z_OK) { // 15 + 32: gzip or zlib header, detected
    error = "zlib: cannot initialize";
    return false;
  }
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  z.avail_in = uInt(compressed.size());
  char chunk[1 << 16];
  int status = Z_OK;
  while (status != Z_STREAM_END) {
    z.next_out = reinterpret_cast<Bytef*>(chunk);
    z.avail_out = sizeof chunk;
    status = inflate(&z, Z_NO_FLUSH);
    if (status != Z_OK && status != Z_STREAM_END) {
      error = std::string("corrupt gzip data (") + (z.msg ? z.msg : "zlib error") + ")";
      inflateEnd(&z);
      return false;
    }
    text.append(chunk, sizeof chunk - z.avail_out);
    if (status == Z_STREAM_END && z.avail_in > 0) { // a further gzip member follows
      inflateReset(&z);
      status = Z_OK;
    }
    if (status == Z_OK && z.avail_in == 0 && z.avail_out != 0) {
      error = "truncated gzip data";
      inflateEnd(&z);
      return false;
    }
  }
  inflateEnd(&z);
  return true;
}

/// Reads the atoms of a .pqr, .pdb, .ent, .cif or .mmcif file (each also as .gz). Never throws for bad input:
/// the result says what is wrong in one line.
inline StructureReadResult ReadStructureFile(const std::string& path,
                                             const StructureReadOptions& options = {}) {
  const StructureFormat format = StructureFormatFromPath(path);
  if (format == StructureFormat::Unknown)
    return StructureReadResult::Failure("'" + path +
                                        "': unknown structure format (use .pqr, .pdb, .ent, .cif or "
                                        ".mmcif, optionally .gz)");
  std::ifstream in(path, std::ios::binary);
  if (!in) return StructureReadResult::Failure("cannot open '" + path + "'");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  std::string text = bytes.str();
  if (text.size() >= 2 && static_cast<unsigned char>(text[0]) == 0x1f &&
      static_cast<unsigned char>(text[1]) == 0x8b) {
    std::string plain, error;
    if (!Gunzip(text, plain, error)) return StructureReadResult::Failure("'" + path + "': " + error);
    text.swap(plain);
  }
  if (format == StructureFormat::Pqr) return ReadPqr(text, path, options);
  if (format == StructureFormat::MmCif) return ReadMmCif(text, path, options);
  return ReadPdb(text, path, options);
}

} // namespace molremesh
