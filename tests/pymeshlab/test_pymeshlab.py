#!/usr/bin/env python3
"""The molremesh plugin in PyMeshLab 2023.12 (Debian's /usr/bin/python3).

Loads the plugin, runs the full pipeline and the quality report on three shared meshes and checks
them against the CLI on the same inputs: PyMeshLab's meshes have double scalars like the CLI's, so
the figures and the output vertices are bit-identical. A refused input raises PyMeshLabException
with our message and leaves the mesh as it was.

Environment (set by ctest): MOLREMESH_CLI (the molremesh binary), MOLREMESH_PYMESHLAB_PLUGIN,
MOLREMESH_SHARED_DATA_DIR, PYTHONPATH (pymeshlab).
"""
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "meshlabserver_scripts" / "pymeshlab"))
import molremesh_pymeshlab as molremesh  # noqa: E402

pymeshlab = molremesh.load()

SHARED = pathlib.Path(os.environ.get("MOLREMESH_SHARED_DATA_DIR", "../shared/data"))
CLI = os.environ.get("MOLREMESH_CLI", "molremesh")
# Three small shared surfaces of different generators (GRASP, MSMS, PyMOL).
MESHES = ["galactose_grasp.ply", "bpti_1bpi_msms.ply", "ubiquitin_1UBQ_pymol_ses.ply"]
# Figures of the filters' output values and their names in the CLI's JSON.
FIGURES = ["vertices", "faces", "q_min", "q_avg", "mean_edge_length", "angle_min_deg", "angle_max_deg",
           "v567_percent", "small_angle_percent", "obtuse_percent", "large_angle_percent", "area",
           "volume", "euler", "components", "boundary_edges", "non_manifold_edges",
           "non_manifold_vertices", "degenerate_faces", "self_intersecting_pairs",
           "self_intersecting_faces"]


def mesh_path(name):
    path = SHARED / "meshes" / name
    if not path.is_file():
        raise unittest.SkipTest(f"shared mesh {path} not found")
    return path


def cli_json(*args):
    result = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if result.returncode != 0:
        raise AssertionError(f"{CLI} {' '.join(map(str, args))}: {result.returncode}\n{result.stderr}")
    return result.stdout


class PluginLoads(unittest.TestCase):
    def test_filters_are_listed(self):
        for name in (molremesh.FULL_PIPELINE, molremesh.QUALITY_REPORT, molremesh.COLOR_BAD_ELEMENTS):
            self.assertIn(name, pymeshlab.filter_list())


class SameAsCli(unittest.TestCase):
    def assert_figures_equal(self, figures, report, what):
        for name in FIGURES:
            self.assertIn(name, figures, f"{what}: no output value {name}")
            self.assertEqual(figures[name], report[name], f"{what}: {name}")

    def test_quality_report(self):
        for name in MESHES:
            with self.subTest(mesh=name):
                path = mesh_path(name)
                ms = pymeshlab.MeshSet()
                ms.load_new_mesh(str(path))
                figures = ms.apply_filter(molremesh.QUALITY_REPORT, selfintersections=True)
                report = json.loads(cli_json("report", "--json", path))
                self.assert_figures_equal(figures, report, name)
                self.assertEqual(figures["genus"], report["genus"] if report["genus"] is not None else -1)

    def test_full_pipeline(self):
        for name in MESHES:
            with self.subTest(mesh=name), tempfile.TemporaryDirectory() as tmp:
                path = mesh_path(name)
                cli_out = pathlib.Path(tmp) / "cli.ply"
                cli_stats = pathlib.Path(tmp) / "cli.json"
                cli_json("remesh", path, cli_out, "--json", cli_stats, "--quiet")
                cli = json.loads(cli_stats.read_text())

                ms = pymeshlab.MeshSet()
                ms.load_new_mesh(str(path))
                # Edge length 0 (the cleaned input's mean edge length), as the CLI's default; the
                # filter's own default is the raw input's mean, which the dialog shows.
                figures = ms.apply_filter(molremesh.FULL_PIPELINE, newlayer=False,
                                          targetlength=molremesh.length_value(pymeshlab, 0.0))
                # The CLI's promises: a valid surface, every target met (or the same misses).
                self.assertEqual(figures["valid"], cli["verdict"]["valid"])
                self.assertEqual(figures["all_targets_met"], cli["verdict"]["all_targets_met"])
                self.assertTrue(figures["valid"])
                self.assertGreaterEqual(figures["angle_min_deg"], 30.0 - 1e-9)
                self.assertLessEqual(figures["angle_max_deg"], 120.0 + 1e-9)
                self.assertEqual(figures["non_manifold_edges"], 0)
                self.assertEqual(figures["self_intersecting_pairs"], 0)
                self.assertEqual(figures["target_edge_length"], cli["target_edge_length"])
                self.assert_figures_equal(figures, cli["stages"][-1]["after"], name)
                self.assert_figures_equal({k[len("input_"):]: v for k, v in figures.items()
                                           if k.startswith("input_")}, cli["input"], name + " input")

                # The output mesh itself: the same vertices and faces as the CLI's file.
                result = ms.current_mesh()
                reference = pymeshlab.MeshSet()
                reference.load_new_mesh(str(cli_out))
                self.assertTrue(np.array_equal(result.vertex_matrix(),
                                               reference.current_mesh().vertex_matrix()))
                self.assertTrue(np.array_equal(result.face_matrix(),
                                               reference.current_mesh().face_matrix()))

    def test_new_layer_keeps_the_input(self):
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(str(mesh_path(MESHES[0])))
        before = ms.current_mesh().vertex_matrix().copy()
        ms.apply_filter("molecular_remesh_clean_raw_mesh")
        self.assertEqual(ms.mesh_number(), 2)
        self.assertTrue(np.array_equal(ms.mesh(0).vertex_matrix(), before))


class SurfaceFromStructure(unittest.TestCase):
    """The creation filter on an empty MeshSet: the CLI's `molremesh surface`, bit for bit."""

    def test_same_surface_as_cli(self):
        structure = SHARED / "structures" / "1UBQ.pqr"
        if not structure.is_file():
            raise unittest.SkipTest(f"shared structure {structure} not found")
        with tempfile.TemporaryDirectory() as tmp:
            cli_out = pathlib.Path(tmp) / "cli.ply"
            cli_json("surface", structure, cli_out, "--quiet")
            ms = pymeshlab.MeshSet()
            figures = ms.apply_filter(molremesh.SURFACE_FROM_STRUCTURE, structurefile=str(structure))
            self.assertEqual(ms.mesh_number(), 1)
            self.assertEqual(figures["atoms"], 602)
            self.assertTrue(figures["valid"])
            self.assertGreaterEqual(figures["angle_min_deg"], 30.0)
            self.assertLessEqual(figures["angle_max_deg"], 90.0 + 1e-6)
            self.assertEqual(figures["self_intersecting_pairs"], 0)
            reference = pymeshlab.MeshSet()
            reference.load_new_mesh(str(cli_out))
            self.assertTrue(np.array_equal(ms.current_mesh().vertex_matrix(),
                                           reference.current_mesh().vertex_matrix()))
            self.assertTrue(np.array_equal(ms.current_mesh().face_matrix(),
                                           reference.current_mesh().face_matrix()))


# PyMeshLab 2023.12 keeps a pointer to the log of a MeshSet whose filter raised, and the next mesh
# load logs through it: a MeshSet that saw an exception must outlive the later loads.
REFUSED_MESH_SETS = []


class RefusedInput(unittest.TestCase):
    def refused(self, ms, filter_name, expected, **parameters):
        REFUSED_MESH_SETS.append(ms)
        mesh = ms.current_mesh()
        vertices, faces = mesh.vertex_matrix().copy(), mesh.face_matrix().copy()
        with self.assertRaises(pymeshlab.PyMeshLabException) as raised:
            ms.apply_filter(filter_name, **parameters)
        self.assertIn(expected, str(raised.exception))
        self.assertEqual(ms.mesh_number(), 1)
        with np.errstate(invalid="ignore"):
            self.assertTrue(np.array_equal(ms.current_mesh().vertex_matrix(), vertices, equal_nan=True))
        self.assertTrue(np.array_equal(ms.current_mesh().face_matrix(), faces))

    def test_non_finite_vertices(self):
        vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, np.nan]], dtype=np.float64)
        faces = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]], dtype=np.int32)
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(vertices, faces))
        self.refused(ms, molremesh.FULL_PIPELINE, "vertices with NaN or infinite coordinates")

    def test_missing_structure_file(self):
        ms = pymeshlab.MeshSet()
        REFUSED_MESH_SETS.append(ms)
        with self.assertRaises(pymeshlab.PyMeshLabException) as raised:
            ms.apply_filter(molremesh.SURFACE_FROM_STRUCTURE, structurefile="/nonexistent/x.pdb")
        self.assertIn("cannot open '/nonexistent/x.pdb'", str(raised.exception))
        self.assertEqual(ms.mesh_number(), 0)

    def test_bad_parameter(self):
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(str(mesh_path(MESHES[0])))
        self.refused(ms, molremesh.FULL_PIPELINE, "Smallest angle must be at least 0 and below 60 degrees",
                     minangle=75.0)


if __name__ == "__main__":
    unittest.main(verbosity=2)
