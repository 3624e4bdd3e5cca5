#!/usr/bin/env bash
# The main job on bundled data, from a fresh clone: installs the dependencies, builds, installs the
# plugin into Debian's MeshLab, then inspects and remeshes real molecular meshes with the CLI and with
# meshlabserver (the full pipeline). Results go to demo_output/ (override with OUT_DIR); pass mesh files to use others.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$repo/build}
out=${OUT_DIR:-$repo/demo_output}
data="$repo/../shared/data/meshes"
meshes=("$@")
[ ${#meshes[@]} -gt 0 ] || meshes=("$data/ubiquitin_1UBQ_edtsurf_mc.ply" "$data/lysozyme_Lys1_msms.ply")

bash "$repo/scripts/install_deps.sh"
BUILD_DIR=$build bash "$repo/scripts/build.sh"

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
echo "== Installing the plugin into MeshLab's plugin folder (and the CLI into /usr/local/bin)"
"${sudo_cmd[@]}" cmake --install "$build"

mkdir -p "$out"
for mesh in "${meshes[@]}"; do
  name=$(basename "${mesh%.*}")
  echo
  echo "== $name: quality report (CLI)"
  "$build/cli/molremesh" report "$mesh"
  echo
  echo "== $name: coloring of bad elements (CLI) -> $out/${name}_colored.ply"
  "$build/cli/molremesh" color "$mesh" "$out/${name}_colored.ply"
  echo
  echo "== $name: the same through Debian's meshlabserver with the installed plugin"
  xvfb-run -a meshlabserver -l "$out/${name}_meshlab_report.log" -i "$mesh" \
    -s "$repo/meshlabserver_scripts/quality_report.mlx" >/dev/null 2>&1
  grep -E "^(LOG: 0 )?(Molecular Remesh|Qmin|V567|obtuse faces|genus|self-intersecting)" \
    "$out/${name}_meshlab_report.log" || cat "$out/${name}_meshlab_report.log"
  xvfb-run -a meshlabserver -l "$out/${name}_meshlab_color.log" -i "$mesh" -o "$out/${name}_meshlab_colored.ply" \
    -m vc fc vq fq -s "$repo/meshlabserver_scripts/color_bad_elements.mlx" >/dev/null 2>&1
  grep -E "(Irregular|Obtuse|Small-angle)" "$out/${name}_meshlab_color.log" || true
  echo "   -> $out/${name}_meshlab_colored.ply (open it in MeshLab: red = irregular vertex / obtuse face," \
       "blue = angle < 30 deg, magenta = both)"
  echo
  echo "== $name: the full pipeline (clean, CVT, valence, segment + RAR, small, obtuse, smooth, polish)" \
       "-> $out/${name}_remeshed.ply"
  "$build/cli/molremesh" remesh "$mesh" "$out/${name}_remeshed.ply" --quiet --json "$out/${name}_remeshed.json"
  "$build/cli/molremesh" color "$out/${name}_remeshed.ply" "$out/${name}_remeshed_colored.ply"
  echo
  echo "== $name: the Full Pipeline filter through meshlabserver -> $out/${name}_meshlab_remeshed.ply"
  xvfb-run -a meshlabserver -l "$out/${name}_meshlab_full.log" -i "$mesh" -o "$out/${name}_meshlab_remeshed.ply" \
    -s "$repo/meshlabserver_scripts/full_pipeline.mlx" >/dev/null 2>&1
  grep -E "(min angle|max angle|V567|obtuse faces|self-intersecting pairs|stage times)" \
    "$out/${name}_meshlab_full.log" | sed 's/^LOG: [0-9] //' | awk '!seen[$0]++' || cat "$out/${name}_meshlab_full.log"
done
echo
echo "Done. The filters are in MeshLab under Filters > Remeshing, Simplification and Reconstruction."
