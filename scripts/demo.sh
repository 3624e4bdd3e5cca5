#!/usr/bin/env bash
# The main job on bundled data, from a fresh clone: installs the dependencies, builds, installs the
# plugin into Debian's MeshLab, then inspects and remeshes real molecular meshes with the CLI and with
# meshlabserver (the full pipeline). The meshes are the bundled ones in data/ (pass mesh files to use
# others); results go to demo_output/ (override with OUT_DIR).
#   --cli-only   only the CLI part, with an already built CLI (MOLREMESH, default BUILD_DIR/cli/molremesh):
#                no install, no build, no meshlabserver
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$repo/build}
out=${OUT_DIR:-$repo/demo_output}
cli_only=false
if [ "${1:-}" = "--cli-only" ]; then
  cli_only=true
  shift
fi
cli=${MOLREMESH:-$build/cli/molremesh}
meshes=("$@")
[ ${#meshes[@]} -gt 0 ] || meshes=("$repo/data/ubiquitin_1UBQ_edtsurf_mc.ply" "$repo/data/lysozyme_Lys1_msms.ply")

if ! $cli_only; then
  bash "$repo/scripts/install_deps.sh"
  BUILD_DIR=$build bash "$repo/scripts/build.sh"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  echo "== Installing the plugin into MeshLab's plugin folder (and the CLI into /usr/local/bin)"
  "${sudo_cmd[@]}" cmake --install "$build"
fi

mkdir -p "$out"
for mesh in "${meshes[@]}"; do
  name=$(basename "${mesh%.*}")
  echo
  echo "== $name: quality report (CLI)"
  "$cli" report "$mesh"
  echo
  echo "== $name: coloring of bad elements (CLI) -> $out/${name}_colored.ply"
  "$cli" color "$mesh" "$out/${name}_colored.ply"
  echo
  echo "== $name: the full pipeline (clean, CVT, valence, segment + RAR, small, obtuse, smooth, polish)" \
       "-> $out/${name}_remeshed.ply"
  "$cli" remesh "$mesh" "$out/${name}_remeshed.ply" --json "$out/${name}_remeshed.json"
  "$cli" color "$out/${name}_remeshed.ply" "$out/${name}_remeshed_colored.ply"
  $cli_only && continue
  echo
  echo "== $name: the same through Debian's meshlabserver with the installed plugin"
  xvfb-run -a meshlabserver -l "$out/${name}_meshlab_report.log" -i "$mesh" \
    -s "$repo/meshlabserver_scripts/quality_report.mlx" >/dev/null 2>&1
  grep -E "^(LOG: 0 )?(Molecular Remesh|Qmin|V567|obtuse faces|genus|self-intersecting)" \
    "$out/${name}_meshlab_report.log" || cat "$out/${name}_meshlab_report.log"
  xvfb-run -a meshlabserver -l "$out/${name}_meshlab_color.log" -i "$mesh" -o "$out/${name}_meshlab_colored.ply" \
    -m vc fc vq fq -s "$repo/meshlabserver_scripts/color_bad_elements.mlx" >/dev/null 2>&1
  grep -E "(Irregular|Obtuse|Small-angle)" "$out/${name}_meshlab_color.log" || true
  echo "   -> $out/${name}_meshlab_colored.ply (open it in MeshLab: faces vermillion = obtuse, blue = an" \
       "angle < 30 deg, reddish purple = both; vertices bluish green = valence < 5, yellow = valence > 7)"
  echo
  echo "== $name: the Full Pipeline filter through meshlabserver -> $out/${name}_meshlab_remeshed.ply"
  xvfb-run -a meshlabserver -l "$out/${name}_meshlab_full.log" -i "$mesh" -o "$out/${name}_meshlab_remeshed.ply" \
    -s "$repo/meshlabserver_scripts/full_pipeline.mlx" >/dev/null 2>&1
  grep -E "(min angle|max angle|V567|obtuse faces|self-intersecting pairs|stage times)" \
    "$out/${name}_meshlab_full.log" | sed 's/^LOG: [0-9] //' | awk '!seen[$0]++' || cat "$out/${name}_meshlab_full.log"
done
echo
$cli_only && exit 0
echo "Done. The filters are in MeshLab under Filters > Remeshing, Simplification and Reconstruction."
