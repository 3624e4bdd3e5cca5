// Reading atoms from PQR and PDB files: counts, skip rules, radii, and one clear error per bad input.
#include <gtest/gtest.h>

#include <vcg_ext/structure/sasa_reference.h>
#include <vcg_ext/structure/structure_file.h>

#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_helpers.h"

namespace {

using molremesh::ReadMmCif;
using molremesh::ReadPdb;
using molremesh::ReadPqr;
using molremesh::ReadStructureFile;
using molremesh::StructureReadOptions;

// Whitespace layout, with a chain (11 fields) and without (10 fields).
const char* kSmallPqr = "REMARK   1 written by hand\n"
                        "ATOM      1  N   MET A   1      27.340  24.430   2.614  0.1592 1.8240\n"
                        "ATOM      2  H   MET A   1      27.000  24.000   2.000  0.1984 0.6000\n"
                        "ATOM      3  CA  MET A   1      26.266  25.413   2.842  0.0221 1.9080\n"
                        "HETATM    4  ZN  ZN2   201      20.000  20.000   0.000  2.0000 1.0900\n"
                        "HETATM    5  O   HOH   301      10.000  10.000  10.000 -0.8340 1.6612\n"
                        "TER\nEND\n";

std::string PdbLine(const std::string& record, int serial, const std::string& name, char altLoc,
                    const std::string& residue, char chain, int resSeq, double x, double y, double z,
                    const std::string& element) {
  char buffer[100];
  std::snprintf(buffer, sizeof buffer, "%-6s%5d %-4s%c%3s %c%4d    %8.3f%8.3f%8.3f  1.00  0.00          %2s",
                record.c_str(), serial, name.c_str(), altLoc, residue.c_str(), chain, resSeq, x, y, z,
                element.c_str());
  return std::string(buffer) + "\n";
}

std::string SmallPdb() {
  return PdbLine("ATOM", 1, " N", ' ', "ALA", 'A', 1, 0, 0, 0, "N") +
         PdbLine("ATOM", 2, " CA", ' ', "ALA", 'A', 1, 1.5, 0, 0, "C") +
         PdbLine("ATOM", 3, " CB", 'A', "ALA", 'A', 1, 2, 1.4, 0, "C") +
         PdbLine("ATOM", 4, " CB", 'B', "ALA", 'A', 1, 2, -1.4, 0, "C") +
         PdbLine("ATOM", 5, " H", ' ', "ALA", 'A', 1, -1, 0, 0, "H") +
         PdbLine("HETATM", 6, "ZN", ' ', " ZN", 'A', 101, 5, 5, 5, "ZN") +
         PdbLine("HETATM", 7, " O", ' ', "HOH", 'A', 201, 9, 9, 9, "O") + "END\n";
}

TEST(StructureReading, PqrKeepsHeavyAtomsAndHetatmSkipsWatersAndHydrogens) {
  const auto r = ReadPqr(kSmallPqr, "small.pqr");
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.atoms.size(), 3u);
  EXPECT_EQ(r.skippedWaters, 1u);
  EXPECT_EQ(r.skippedHydrogens, 1u);
  EXPECT_EQ(r.atoms[0].name, "N");
  EXPECT_EQ(r.atoms[0].chain, 'A');
  EXPECT_DOUBLE_EQ(r.atoms[1].radius, 1.908);
  EXPECT_DOUBLE_EQ(r.atoms[1].position[0], 26.266);
  EXPECT_TRUE(r.atoms[2].hetatm);
}

TEST(StructureReading, PqrOptionsKeepEachSkippedKind) {
  StructureReadOptions options;
  options.keepWaters = true;
  options.keepHydrogens = true;
  EXPECT_EQ(ReadPqr(kSmallPqr, "small.pqr", options).atoms.size(), 5u);
  options = {};
  options.keepHetatm = false;
  const auto r = ReadPqr(kSmallPqr, "small.pqr", options);
  EXPECT_EQ(r.atoms.size(), 2u);
  EXPECT_EQ(r.skippedHetatm, 1u);
}

TEST(StructureReading, PqrColumnLayoutWithRunTogetherFieldsIsRead) {
  // pdb2pqr's default output: chain and a 4-digit residue number, and two coordinates, run together.
  const std::string text = "ATOM   2245  CB  TRP A1526      92.711 -20.659-100.085  0.0339 1.9080\n"
                           "ATOM      1  N   GLU A1385      49.582 -13.570 -86.279  0.0017 1.8240\n";
  const auto r = ReadPqr(text, "columns.pqr");
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.atoms.size(), 2u);
  EXPECT_EQ(r.atoms[0].residueNumber, 1526);
  EXPECT_EQ(r.atoms[0].chain, 'A');
  EXPECT_DOUBLE_EQ(r.atoms[0].position[2], -100.085);
  EXPECT_DOUBLE_EQ(r.atoms[1].radius, 1.824);
}

void ExpectError(const molremesh::StructureReadResult& r, const std::string& part) {
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.atoms.empty());
  EXPECT_NE(r.message.find(part), std::string::npos) << r.message;
  EXPECT_EQ(r.message.find('\n'), std::string::npos) << "one line: " << r.message;
}

TEST(StructureReading, PqrErrorsNameTheLine) {
  ExpectError(ReadPqr("REMARK nothing\nEND\n", "empty.pqr"), "no atoms");
  ExpectError(ReadPqr("ATOM 1 N MET A 1 1.0 2.0 3.0 0.1 1.5\nATOM 2 CA MET A 1 1.0 2.0\n", "t.pqr"),
              "line 2: truncated record");
  ExpectError(ReadPqr("ATOM 1 N MET A 1 nan 2.0 3.0 0.1 1.5\n", "n.pqr"), "line 1: coordinate is NaN");
  ExpectError(ReadPqr("ATOM 1 N MET A 1 1.0 2.0 3.0 0.1 -1.5\n", "r.pqr"), "line 1: bad radius -1.5");
  ExpectError(ReadPqr("ATOM 1 N MET A 1 1.0 2.0 3.0 0.1 nan\n", "r.pqr"), "bad radius");
  ExpectError(ReadPqr("ATOM 1 N MET A 1 1.0 2.0 3.0 0.1 1.5x\n", "r.pqr"), "bad number '1.5x'");
  ExpectError(ReadPqr("ATOM 1 H MET A 1 1.0 2.0 3.0 0.1 1.0\n", "h.pqr"), "no atoms");
}

TEST(StructureReading, PdbRadiiFromProtOrAndTheSkipRules) {
  const auto r = ReadPdb(SmallPdb(), "small.pdb");
  ASSERT_TRUE(r.ok) << r.message;
  // N, CA, CB (location A), ZN; the hydrogen, the water and location B skipped.
  ASSERT_EQ(r.atoms.size(), 4u);
  EXPECT_EQ(r.skippedHydrogens, 1u);
  EXPECT_EQ(r.skippedWaters, 1u);
  EXPECT_EQ(r.skippedAltLocs, 1u);
  EXPECT_DOUBLE_EQ(r.atoms[2].position[1], 1.4);
  EXPECT_NEAR(r.atoms[0].radius, 1.64, 1e-9); // ProtOr N3H0 / N3H1 backbone nitrogen
  EXPECT_NEAR(r.atoms[1].radius, 1.88, 1e-9); // ProtOr C4H1
  EXPECT_TRUE(r.atoms[3].hetatm);
  EXPECT_EQ(r.atoms[3].element, "ZN");
  EXPECT_GT(r.atoms[3].radius, 0);

  StructureReadOptions all;
  all.keepWaters = all.keepHydrogens = all.allAltLocs = true;
  EXPECT_EQ(ReadPdb(SmallPdb(), "small.pdb", all).atoms.size(), 7u);
  StructureReadOptions noHet;
  noHet.keepHetatm = false;
  EXPECT_EQ(ReadPdb(SmallPdb(), "small.pdb", noHet).atoms.size(), 3u);
  StructureReadOptions naccess;
  naccess.radii = StructureReadOptions::Radii::Naccess;
  const auto n = ReadPdb(SmallPdb(), "small.pdb", naccess);
  ASSERT_TRUE(n.ok) << n.message;
  EXPECT_NEAR(n.atoms[1].radius, 1.87, 1e-9); // NACCESS aliphatic carbon
}

TEST(StructureReading, PdbErrorsNameTheLine) {
  ExpectError(ReadPdb("HEADER nothing\nEND\n", "e.pdb"), "no atoms");
  const std::string good = PdbLine("ATOM", 1, " N", ' ', "ALA", 'A', 1, 0, 0, 0, "N");
  ExpectError(ReadPdb(good + good.substr(0, 40) + "\n", "t.pdb"), "line 2: truncated record");
  std::string nan = good;
  nan.replace(30, 8, "     nan");
  ExpectError(ReadPdb(good + nan, "n.pdb"), "line 2: coordinate is NaN");
  ExpectError(ReadPdb(PdbLine("HETATM", 1, "XX", ' ', "UNK", 'A', 1, 0, 0, 0, "XX"), "u.pdb"),
              "line 1: unknown element 'XX'");
}

TEST(StructureReading, OldPdbElementColumnsAreNotTakenAsElements) {
  // Old files carry a segment id and line number in columns 73-80; freesasa would read "17".
  std::string line = PdbLine("HETATM", 1519, " C1", ' ', "478", ' ', 200, 11.169, 14.977, 2.445, "");
  line.replace(72, 8, "1HPV1704");
  const auto r = ReadPdb(line, "old.pdb");
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.atoms[0].element, "C");
  EXPECT_GT(r.atoms[0].radius, 1.5);
}

TEST(StructureReading, FilesByExtensionAndGzip) {
  const auto dir = molremesh::test::TempDir("structure_reading");
  std::ofstream(dir / "small.pqr") << kSmallPqr;
  const std::string pdb = SmallPdb();
  gzFile gz = gzopen((dir / "small.pdb.gz").c_str(), "wb");
  gzwrite(gz, pdb.data(), unsigned(pdb.size()));
  gzclose(gz);
  EXPECT_EQ(ReadStructureFile((dir / "small.pqr").string()).atoms.size(), 3u);
  const auto r = ReadStructureFile((dir / "small.pdb.gz").string());
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.atoms.size(), 4u);
  std::ofstream(dir / "bad.pdb.gz") << std::string("\x1f\x8b\x08\x00garbage", 12);
  ExpectError(ReadStructureFile((dir / "bad.pdb.gz").string()), "gzip");
  ExpectError(ReadStructureFile((dir / "x.cif").string()), "cannot open");
  ExpectError(ReadStructureFile((dir / "x.xyz").string()), "unknown structure format");
  ExpectError(ReadStructureFile((dir / "missing.pqr").string()), "cannot open");
  std::filesystem::remove_all(dir);
}

// --- mmCIF ----------------------------------------------------------------------------------------

/// The atom records of a PDB text as an mmCIF _atom_site loop (the columns the wwPDB writes), one
/// row per ATOM/HETATM line of the first model; `model` numbers the rows' model.
std::string AtomSitesOfPdb(const std::string& pdb, int model = 1) {
  std::ostringstream cif;
  cif << "data_test\n#\nloop_\n";
  for (const char* column :
       {"group_PDB", "id", "type_symbol", "label_atom_id", "label_alt_id", "label_comp_id", "label_asym_id",
        "label_seq_id", "pdbx_PDB_ins_code", "Cartn_x", "Cartn_y", "Cartn_z", "auth_seq_id", "auth_comp_id",
        "auth_asym_id", "auth_atom_id", "pdbx_PDB_model_num"})
    cif << "_atom_site." << column << "\n";
  std::istringstream in(pdb);
  auto field = [](const std::string& line, std::size_t at, std::size_t n) {
    std::string v = line.size() > at ? line.substr(at, n) : "";
    v.erase(0, v.find_first_not_of(' '));
    v.erase(v.find_last_not_of(' ') + 1);
    return v.empty() ? std::string("?") : v;
  };
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("ENDMDL", 0) == 0) break;
    if (line.rfind("ATOM", 0) != 0 && line.rfind("HETATM", 0) != 0) continue;
    const std::string alt = field(line, 16, 1), ins = field(line, 26, 1);
    cif << field(line, 0, 6) << " " << field(line, 6, 5) << " " << field(line, 76, 2) << " "
        << field(line, 12, 4) << " " << (alt == "?" ? "." : alt) << " " << field(line, 17, 3) << " "
        << field(line, 21, 1) << " " << field(line, 22, 4) << " " << ins << " " << field(line, 30, 8) << " "
        << field(line, 38, 8) << " " << field(line, 46, 8) << " " << field(line, 22, 4) << " "
        << field(line, 17, 3) << " " << field(line, 21, 1) << " " << field(line, 12, 4) << " " << model
        << "\n";
  }
  return cif.str() + "#\n";
}

void ExpectSameAtoms(const molremesh::StructureReadResult& a, const molremesh::StructureReadResult& b) {
  ASSERT_TRUE(a.ok) << a.message;
  ASSERT_TRUE(b.ok) << b.message;
  ASSERT_EQ(a.atoms.size(), b.atoms.size());
  for (std::size_t i = 0; i < a.atoms.size(); ++i) {
    EXPECT_EQ(a.atoms[i].position, b.atoms[i].position) << i;
    EXPECT_EQ(a.atoms[i].radius, b.atoms[i].radius) << i << " " << a.atoms[i].name;
    EXPECT_EQ(a.atoms[i].name, b.atoms[i].name) << i;
    EXPECT_EQ(a.atoms[i].element, b.atoms[i].element) << i;
    EXPECT_EQ(a.atoms[i].residueName, b.atoms[i].residueName) << i;
    EXPECT_EQ(a.atoms[i].residueNumber, b.atoms[i].residueNumber) << i;
    EXPECT_EQ(a.atoms[i].chain, b.atoms[i].chain) << i;
    EXPECT_EQ(a.atoms[i].hetatm, b.atoms[i].hetatm) << i;
  }
  EXPECT_EQ(a.skippedWaters, b.skippedWaters);
  EXPECT_EQ(a.skippedHydrogens, b.skippedHydrogens);
  EXPECT_EQ(a.skippedHetatm, b.skippedHetatm);
  EXPECT_EQ(a.skippedAltLocs, b.skippedAltLocs);
}

TEST(StructureReading, MmCifGivesThePdbReadersAtomsAndRadii) {
  ExpectSameAtoms(ReadMmCif(AtomSitesOfPdb(SmallPdb()), "small.cif"), ReadPdb(SmallPdb(), "small.pdb"));
  StructureReadOptions all;
  all.keepWaters = all.keepHydrogens = all.allAltLocs = true;
  all.radii = StructureReadOptions::Radii::Naccess;
  ExpectSameAtoms(ReadMmCif(AtomSitesOfPdb(SmallPdb()), "small.cif", all),
                  ReadPdb(SmallPdb(), "small.pdb", all));
  // A whole protein: ubiquitin, 602 heavy atoms and 58 waters.
  std::ifstream in(std::string(MOLREMESH_BUNDLED_DATA_DIR) + "/1UBQ.pdb");
  std::ostringstream pdb;
  pdb << in.rdbuf();
  ASSERT_FALSE(pdb.str().empty());
  const auto fromCif = ReadMmCif(AtomSitesOfPdb(pdb.str()), "1UBQ.cif");
  ExpectSameAtoms(fromCif, ReadPdb(pdb.str(), "1UBQ.pdb"));
  EXPECT_GT(fromCif.atoms.size(), 600u);
}

TEST(StructureReading, MmCifFirstModelGzipAndErrors) {
  const std::string one = AtomSitesOfPdb(SmallPdb(), 1), two = AtomSitesOfPdb(SmallPdb(), 2);
  // A second model's rows after the first: only the first is read.
  const std::string rowsOfTwo = two.substr(two.find("ATOM"), two.rfind("#") - two.find("ATOM"));
  const auto models = ReadMmCif(one.substr(0, one.rfind("#")) + rowsOfTwo + "#\n", "models.cif");
  ASSERT_TRUE(models.ok) << models.message;
  EXPECT_EQ(models.atoms.size(), 4u);

  const auto dir = molremesh::test::TempDir("structure_reading_cif");
  gzFile gz = gzopen((dir / "small.cif.gz").c_str(), "wb");
  gzwrite(gz, one.data(), unsigned(one.size()));
  gzclose(gz);
  const auto r = ReadStructureFile((dir / "small.cif.gz").string());
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.atoms.size(), 4u);
  std::filesystem::remove_all(dir);

  std::string nan = one;
  nan.replace(nan.find("1.500"), 5, "nan  ");
  ExpectError(ReadMmCif(nan, "nan.cif"), "atom site row 2: coordinate is NaN");
  std::string bad = one;
  bad.replace(bad.find("1.500"), 5, "1.5x ");
  ExpectError(ReadMmCif(bad, "bad.cif"), "atom site row 2: bad coordinate '1.5x'");
  ExpectError(ReadMmCif("data_x\n_cell.length_a 10\n", "empty.cif"), "no atoms");
  ExpectError(ReadMmCif("data_x\nloop_\n_atom_site.id\n'unterminated\n", "broken.cif"),
              "not a valid CIF file");
  ExpectError(ReadMmCif("", "nothing.cif"), "no data block");
  std::string unknown = one;
  unknown.replace(unknown.find(" ZN ZN "), 7, " XX XX ");
  ExpectError(ReadMmCif(unknown, "unknown.cif"), "unknown element 'XX'");
}

TEST(StructureReading, FreesasaAreaOfOneSphere) {
  molremesh::Atom a;
  a.position = molremesh::Point(1, 2, 3);
  a.radius = 2.0;
  const double area = molremesh::FreesasaArea({a}, {});
  EXPECT_NEAR(area, 4 * molremesh::kPi * 3.4 * 3.4, 1e-6 * area);
}

// Counts checked against the records of each file (awk): kept atoms, hydrogens by name outside waters,
// water atoms (1UBQ.pqr: 58 waters with their hydrogens; 4JSV: 22128 ATOM and 66 ligand HETATM).
TEST(StructureReadingShared, AtomCountsOfTheSharedStructures) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  using molremesh::test::SharedStructure;
  struct Case {
    const char* file;
    std::size_t atoms, hydrogens, waters;
  };
  const Case cases[] = {{"1UBQ.pqr", 602, 629, 174},         {"bpti_1bpi.pqr", 892, 0, 0},
                        {"lysozyme_Lys1.pqr", 1001, 322, 0}, {"1UBQ.pdb", 602, 0, 58},
                        {"1HPV.pdb", 1551, 0, 80},           {"4JSV.pdb.gz", 22194, 0, 0}};
  for (const Case& c : cases) {
    const auto r = ReadStructureFile(SharedStructure(c.file));
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.atoms.size(), c.atoms) << c.file;
    EXPECT_EQ(r.skippedHydrogens, c.hydrogens) << c.file;
    EXPECT_EQ(r.skippedWaters, c.waters) << c.file;
    // PQR radii may be 0 (AMBER's hydroxyl hydrogens, which BPTI's file does not name as such).
    for (const auto& a : r.atoms) ASSERT_GE(a.radius, 0) << c.file << " atom " << a.name;
  }
}

TEST(StructureReadingShared, ColumnLayoutPqrOfMtorIsReadWhole) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  StructureReadOptions options;
  options.keepHydrogens = true;
  const auto r = ReadStructureFile(molremesh::test::SharedStructure("4JSV.pqr.gz"), options);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.atoms.size(), 44016u);
}

TEST(StructureReadingShared, ProtOrSasaOfUbiquitinAsTheFreesasaProgram) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  // `freesasa 1UBQ.pdb` (Lee-Richards, ProtOr, probe 1.4, no HETATM): Total 4804.06.
  StructureReadOptions options;
  options.keepHetatm = false;
  const auto r = ReadStructureFile(molremesh::test::SharedStructure("1UBQ.pdb"), options);
  ASSERT_TRUE(r.ok) << r.message;
  molremesh::SasaParams program;
  program.resolution = 20; // the freesasa program's default slices per atom
  EXPECT_NEAR(molremesh::FreesasaArea(r.atoms, program), 4804.06, 0.01);
}

} // namespace
