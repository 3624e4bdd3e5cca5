// cgal_isotropic_remesh IN OUT --target L [--iterations 10]
//
// The CGAL baseline of the benchmarks: CGAL::Polygon_mesh_processing::isotropic_remeshing
// (Botsch & Kobbelt 2004, as implemented in CGAL 5.5) with every option at CGAL's default except
// the target edge length and the number of iterations. The input is read the way a CGAL user
// reads a file of unknown quality: as a polygon soup, repaired (repair_polygon_soup), oriented
// (orient_polygon_soup, which duplicates non-manifold vertices and edges so that the soup becomes
// a valid halfedge mesh) and turned into a Surface_mesh (polygon_soup_to_polygon_mesh). Nothing
// is protected: no constrained edges, no feature detection.
//
// Writes OUT (.ply binary or .off, double precision) and prints one JSON object on stdout:
// input/soup/output counts and "remesh_seconds", the wall time of isotropic_remeshing alone.
// Exit status 0 on success, 2 on unreadable input or a CGAL failure, 1 on usage errors.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <chrono>
#include <cstdlib>
#include <exception>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

constexpr const char* kUsage = "usage: cgal_isotropic_remesh IN OUT --target L [--iterations 10]\n";

[[noreturn]] void Fail(int code, const std::string& message) {
  std::cerr << "cgal_isotropic_remesh: error: " << message << '\n';
  if (code == 1) std::cerr << kUsage;
  std::exit(code);
}

double ParseNumber(const std::string& flag, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0') Fail(1, flag + " needs a number, got '" + text + "'");
  return value;
}

} // namespace

int main(int argc, char** argv) {
  std::string input, output;
  double target = -1;
  int iterations = 10;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) Fail(1, arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--target")
      target = ParseNumber(arg, next());
    else if (arg == "--iterations")
      iterations = int(ParseNumber(arg, next()));
    else if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (!arg.empty() && arg[0] == '-')
      Fail(1, "unknown option " + arg);
    else if (input.empty())
      input = arg;
    else if (output.empty())
      output = arg;
    else
      Fail(1, "too many arguments");
  }
  if (input.empty() || output.empty()) Fail(1, "IN and OUT are required");
  if (!(target > 0)) Fail(1, "--target L (a positive edge length) is required");
  if (iterations < 1) Fail(1, "--iterations must be at least 1");

  try {
    std::vector<Point> points;
    std::vector<std::vector<std::size_t>> polygons;
    if (!CGAL::IO::read_polygon_soup(input, points, polygons) || polygons.empty())
      Fail(2, "cannot read a polygon soup from '" + input + "'");
    const std::size_t inputPoints = points.size(), inputPolygons = polygons.size();

    PMP::repair_polygon_soup(points, polygons);
    const bool orientedWithoutDuplication = PMP::orient_polygon_soup(points, polygons);
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons))
      Fail(2, "the repaired soup of '" + input + "' is still not a polygon mesh");
    Mesh mesh;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    const std::size_t soupFaces = mesh.number_of_faces();
    if (!CGAL::is_triangle_mesh(mesh)) PMP::triangulate_faces(mesh);

    const auto start = std::chrono::steady_clock::now();
    PMP::isotropic_remeshing(faces(mesh), target, mesh,
                             CGAL::parameters::number_of_iterations(unsigned(iterations)));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    mesh.collect_garbage();

    if (!CGAL::IO::write_polygon_mesh(output, mesh, CGAL::parameters::stream_precision(17)))
      Fail(2, "cannot write '" + output + "'");

    std::cout << std::setprecision(6) << "{\"input_points\": " << inputPoints
              << ", \"input_polygons\": " << inputPolygons << ", \"mesh_vertices_before\": " << points.size()
              << ", \"mesh_faces_before\": " << soupFaces
              << ", \"oriented_without_duplication\": " << (orientedWithoutDuplication ? "true" : "false")
              << ", \"output_vertices\": " << mesh.number_of_vertices()
              << ", \"output_faces\": " << mesh.number_of_faces() << ", \"target_edge_length\": " << target
              << ", \"iterations\": " << iterations << ", \"remesh_seconds\": " << seconds << "}\n";
  } catch (const std::exception& e) {
    Fail(2, std::string("CGAL failed: ") + e.what());
  }
  return 0;
}
