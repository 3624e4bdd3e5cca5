"""Shared part of the PyMeshLab scripts: finds PyMeshLab and the molremesh plugin, loads both.

PyMeshLab: an installed wheel (`import pymeshlab` works), else the package that
scripts/build_pymeshlab.sh builds into its cache (MOLREMESH_PYMESHLAB_DIR, default
~/.cache/molremesh/pymeshlab-2023.12). The plugin: MOLREMESH_PYMESHLAB_PLUGIN, else the build's
build/plugins2023/libfilter_molremesh.so (cmake -DMOLREMESH_MESHLAB_API=2023 or both).
"""
import os
import pathlib
import sys

REPO = pathlib.Path(__file__).resolve().parents[2]

# PyMeshLab's names of the molremesh filters (MeshLab's menu names, lower case, '_' for blanks).
FULL_PIPELINE = "molecular_remesh_full_pipeline"
QUALITY_REPORT = "molecular_remesh_quality_report"
COLOR_BAD_ELEMENTS = "molecular_remesh_color_bad_elements"
SURFACE_FROM_STRUCTURE = "molecular_remesh_surface_from_structure_file"


def pymeshlab_cache_dir():
    default = pathlib.Path(os.environ.get("XDG_CACHE_HOME", pathlib.Path.home() / ".cache"))
    return pathlib.Path(os.environ.get("MOLREMESH_PYMESHLAB_DIR",
                                       default / "molremesh" / "pymeshlab-2023.12"))


def cache_interpreter():
    """The Python the cache's PyMeshLab is built for (scripts/build_pymeshlab.sh records it)."""
    recorded = pymeshlab_cache_dir() / "interpreter"
    return recorded.read_text().strip() if recorded.is_file() else "/usr/bin/python3"


def rerun_with_cache_interpreter():
    """A script started by another Python (a pyenv or venv python3 first on PATH, without the
    cache's numpy or ABI) runs again under the cache's own interpreter, once."""
    interpreter = cache_interpreter()
    script = sys.argv[0] if sys.argv else ""
    if (os.environ.get("MOLREMESH_PYMESHLAB_RERUN") or not os.path.isfile(script)
            or not os.access(interpreter, os.X_OK)
            or os.path.realpath(sys.executable) == os.path.realpath(interpreter)):
        return
    os.environ["MOLREMESH_PYMESHLAB_RERUN"] = "1"
    os.execv(interpreter, [interpreter, *sys.argv])


def import_pymeshlab():
    """The pymeshlab module: an installed one, else the cache's."""
    try:
        import pymeshlab  # noqa: F401
    except ImportError:
        sys.path.insert(0, str(pymeshlab_cache_dir() / "python"))
        try:
            import pymeshlab  # noqa: F401
        except ImportError as error:
            rerun_with_cache_interpreter()
            sys.exit(f"molremesh: cannot import pymeshlab ({error}) in {sys.executable}; run "
                     "scripts/build_pymeshlab.sh or install a PyMeshLab 2023.12 wheel")
    import pymeshlab
    return pymeshlab


def plugin_path():
    path = pathlib.Path(os.environ.get("MOLREMESH_PYMESHLAB_PLUGIN",
                                       REPO / "build" / "plugins2023" / "libfilter_molremesh.so"))
    if not path.is_file():
        sys.exit(f"molremesh: plugin {path} not found; build it with cmake -DMOLREMESH_MESHLAB_API=2023 "
                 "(or both) and `cmake --build build --target filter_molremesh_2023`, or set "
                 "MOLREMESH_PYMESHLAB_PLUGIN")
    return path


def load():
    """pymeshlab with the molremesh filters loaded."""
    pymeshlab = import_pymeshlab()
    if FULL_PIPELINE not in pymeshlab.filter_list():
        pymeshlab.load_plugin(str(plugin_path()))
    return pymeshlab


def length_value(pymeshlab, value):
    """An edge length in the mesh's units for a Length parameter (absolute, not % of the diagonal)."""
    absolute = getattr(pymeshlab, "PureValue", None) or getattr(pymeshlab, "AbsoluteValue")
    return absolute(value)


def print_figures(figures, stream=sys.stdout):
    for name in sorted(figures):
        print(f"{name} {figures[name]}", file=stream)
