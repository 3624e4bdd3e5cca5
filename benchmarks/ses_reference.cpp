// The analytic solvent-excluded surface of a structure file's atoms, by BALL (libball1.5's
// calculateSESArea and calculateSESVolume), as JSON: the reference for the SES that
// `molremesh surface` extracts. The atoms and radii are molremesh's own (its reader, its
// defaults), so both measure the same balls. Usage: ses_reference STRUCTURE [--probe R]
#include <vcg_ext/structure/structure_file.h>

#include <BALL/KERNEL/atom.h>
#include <BALL/KERNEL/molecule.h>
#include <BALL/KERNEL/system.h>
#include <BALL/STRUCTURE/analyticalSES.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  std::string path;
  double probe = 1.4;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--probe" && i + 1 < argc)
      probe = std::atof(argv[++i]);
    else
      path = a;
  }
  if (path.empty()) {
    std::cerr << "usage: ses_reference STRUCTURE [--probe R]\n";
    return 2;
  }
  const molremesh::StructureReadResult read = molremesh::ReadStructureFile(path);
  if (!read.ok) {
    std::cerr << "ses_reference: " << read.message << "\n";
    return 2;
  }
  BALL::System system;
  auto* molecule = new BALL::Molecule; // owned by the system
  system.insert(*molecule);
  for (const molremesh::Atom& a : read.atoms) {
    auto* atom = new BALL::Atom; // owned by the molecule
    atom->setPosition(BALL::Vector3(float(a.position[0]), float(a.position[1]), float(a.position[2])));
    atom->setRadius(float(a.radius));
    molecule->insert(*atom);
  }
  const auto start = std::chrono::steady_clock::now();
  const double area = BALL::calculateSESArea(system, float(probe));
  const double volume = BALL::calculateSESVolume(system, float(probe));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json out = {{"structure", path}, {"atoms", read.atoms.size()}, {"probe", probe},
                        {"ses_area", area},  {"ses_volume", volume},       {"seconds", seconds}};
  std::cout << out.dump(2) << "\n";
  return 0;
}
