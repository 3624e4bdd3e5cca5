#!/usr/bin/env bash
# Regenerates the README pictures in docs/images/: two shared meshes before and after remeshing,
# colored by the plugin's Color Bad Elements (through the build's sandboxed meshlabserver), shown in
# Debian's real MeshLab GUI under Xvfb and captured with ImageMagick's `import -window root`; then the
# plugin in the GUI itself: the colors and legend right after Color Bad Elements, the Full Pipeline
# dialog, and the log with the new layer after it ran.
#
# usage: scripts/make_pictures.sh [BUILD_DIR]          (default BUILD_DIR: build)
# environment:
#   STAGES   stages for `molremesh remesh --stages` (default: empty = the full pipeline)
#   MESHES   names under ../shared/data/meshes, without .ply
#            (default: lysozyme_Lys1_msms ubiquitin_1UBQ_edtsurf_mc)
#   DATA_DIR folder of the shared meshes (default: ../shared/data/meshes beside the repository)
#   OUT_DIR  where the PNGs go (default: docs/images)
#   ZOOM     mouse-wheel steps into the default MeshLab view (default: 2)
#   WIDTH    width of the saved PNGs in pixels (default: 640)
#   PARTS    which pictures: "meshes", "gui", "region" or any of them (default: "meshes gui region")
#   REGION_CENTER  x y z of the pocket the region pictures select, in the first mesh's coordinates
#            (default: a pocket of lysozyme facing MeshLab's default view, the vertex with the
#            largest z minus distance from the vertical axis through the centroid), radius 8
#
# For each mesh and for its input and remeshed output, two pictures:
#   <mesh>_<input|remeshed>_faces.png     per-face color: obtuse vermillion, angle < 30 deg blue, both
#                                         reddish purple, others light gray (flat shading)
#   <mesh>_<input|remeshed>_vertices.png  per-vertex color: interior vertices of valence below 5 bluish
#                                         green, above 7 yellow, others light gray
# MeshLab opens a generated .mlp project whose RenderingOption selects the color mode, the
# layer dialog, trackball and info panel are hidden with xdotool, and MeshLab is closed again.
# Then, on the first mesh, a private copy of the MeshLab GUI that loads the build's plugin (1600x1000):
#   gui_color_bad_elements.png  the view and the legend in the log right after Color Bad Elements
#   gui_full_pipeline_dialog.png the Full Pipeline dialog with its pre-filled values
#   gui_full_pipeline_log.png   the layers and the log (aligned tables) after the Full Pipeline ran
#   gui_region_dialog.png       a pocket selected with MeshLab's Conditional Face Selection, and the
#                               Full Pipeline dialog with "Remesh only selected faces" on
#   gui_region_remeshed.png     the result in wireframe: the new pocket (selected, red) in the
#                               untouched input, the new layer and the log of the region run
set -euo pipefail

# Inside the virtual display (the script calls itself through xvfb-run): capture one project.
if [ "${1:-}" = "--capture" ]; then
  project=$2 png=$3 zoom=$4
  meshlab "$project" >"$png.meshlab.log" 2>&1 &
  pid=$!
  win=
  for _ in $(seq 1 120); do
    win=$(xdotool search --onlyvisible --name '^MeshLab ' 2>/dev/null | head -1 || true)
    [ -n "$win" ] && break
    kill -0 "$pid" 2>/dev/null || { echo "make_pictures: meshlab exited early" >&2; cat "$png.meshlab.log" >&2; exit 1; }
    sleep 0.5
  done
  [ -n "$win" ] || { echo "make_pictures: no MeshLab window after 60 s" >&2; kill "$pid"; exit 1; }
  # Wait until the mesh is loaded (MeshLab logs it), then, as there is no window manager under
  # Xvfb, place and size the main window ourselves until it keeps that size.
  for _ in $(seq 1 120); do
    grep -q 'All files opened\|Opened mesh' "$png.meshlab.log" && break
    sleep 0.5
  done
  stable=0
  for _ in $(seq 1 40); do
    xdotool windowmove "$win" 0 0 windowsize "$win" 1280 960 2>/dev/null || true
    sleep 0.5
    if xdotool getwindowgeometry "$win" 2>/dev/null | grep -q 'Geometry: 1280x960'; then
      stable=$((stable + 1))
      [ "$stable" -ge 3 ] && break
    else
      stable=0
    fi
  done
  [ "$stable" -ge 3 ] || { echo "make_pictures: could not size the MeshLab window" >&2; kill "$pid"; exit 1; }
  sleep 1
  xdotool windowfocus --sync "$win" 2>/dev/null || true
  xdotool key --window "$win" ctrl+l # hide the layer dialog
  sleep 0.3
  xdotool key --window "$win" shift+h # hide the trackball
  sleep 0.3
  xdotool key alt+v p # View > Show Info Panel (off)
  sleep 0.3
  xdotool mousemove 640 498
  for _ in $(seq 1 "$zoom"); do
    xdotool click 5 # wheel: zoom in
    sleep 0.2
  done
  xdotool mousemove 1279 959
  sleep 2
  import -window root "$png"
  xdotool key ctrl+q 2>/dev/null || true # File > Exit (the window may be gone before the key up)
  for _ in $(seq 1 20); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.5
  done
  kill "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  exit 0
fi

# Inside the virtual display: MeshLab (the plugin's private copy) started on a mesh, its window at
# 1600x1000 once the mesh is loaded; sets pid and win (usage: start_gui MESHLAB MESH LOG).
start_gui() {
  "$1" "$2" >"$3" 2>&1 &
  pid=$!
  win=
  for _ in $(seq 1 120); do
    win=$(xdotool search --onlyvisible --name '^MeshLab ' 2>/dev/null | head -1 || true)
    [ -n "$win" ] && break
    sleep 0.5
  done
  [ -n "$win" ] || { echo "make_pictures: no MeshLab window after 60 s" >&2; kill "$pid"; exit 1; }
  for _ in $(seq 1 120); do
    grep -q 'All files opened\|Opened mesh' "$3" && break
    sleep 0.5
  done
  sleep 3
  xdotool windowmove "$win" 0 0 windowsize "$win" 1600 1000
  sleep 2
}
# Opens a filter's dialog through MeshLab's filter search (ctrl+f), the first hit for $1; its
# window (title $1) sets WIDTH and HEIGHT.
open_dialog() {
  xdotool windowfocus --sync "$win" 2>/dev/null || true
  xdotool key --window "$win" ctrl+f
  sleep 1
  xdotool type --delay 40 "$1"
  sleep 1.5
  xdotool key Down
  sleep 0.5
  xdotool key Return
  sleep 3
  dialog=$(xdotool search --onlyvisible --name "$1" | head -1)
  [ -n "$dialog" ] || { echo "make_pictures: no dialog of $1" >&2; kill "$pid"; exit 1; }
  eval "$(xdotool getwindowgeometry --shell "$dialog")"
}

# Closes MeshLab (File > Exit, then no to saving) and ends the mode.
quit_gui() {
  xdotool key ctrl+q 2>/dev/null || true
  sleep 2
  xdotool key Escape 2>/dev/null || true
  kill "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  exit 0
}

# Inside the virtual display: the plugin in a MeshLab GUI that loads it (usage: --gui MESHLAB MESH OUT).
if [ "${1:-}" = "--gui" ]; then
  start_gui "$2" "$3" "$4/gui.meshlab.log"
  out=$4
  cpu() { awk '{print $14 + $15}' "/proc/$pid/stat"; }
  open_filter() { open_dialog "Molecular Remesh: $1"; }
  # Clicks the dialog's Apply (bottom right) and waits until MeshLab stops working.
  apply_filter() {
    xdotool mousemove $((WIDTH * 74 / 100)) $((HEIGHT - 22)) click 1
    local before
    sleep 3
    for _ in $(seq 1 600); do
      before=$(cpu)
      sleep 2
      [ "$(cpu)" -le $((before + 20)) ] && break
    done
    sleep 1
  }
  open_filter "Color Bad Elements"
  apply_filter
  xdotool mousemove 1599 999
  import -window root "$out/gui_color_bad_elements.png"
  open_filter "Full Pipeline"
  import -window root -crop "${WIDTH}x${HEIGHT}+0+0" +repage "$out/gui_full_pipeline_dialog.png"
  apply_filter
  # Done when the new layer is there: the second row of the layer list turns to the selection color.
  for _ in $(seq 1 900); do
    pixel=$(import -window root -crop 1x1+1300+145 +repage txt:- | tail -1 | grep -o '#[0-9A-F]\{6\}' || true)
    [ -n "$pixel" ] && [ "$pixel" != "#FFFFFF" ] && break
    sleep 2
  done
  sleep 3
  # A taller log pane: the layer dock floated (double click on its title) and stretched down the
  # tall screen below the main window; the log takes a third of the extra height.
  xdotool mousemove 1300 78 click --repeat 2 --delay 120 1
  sleep 2
  dock=$(xdotool search --onlyvisible --name '^Project_1$' | head -1)
  [ -n "$dock" ] && xdotool windowmove "$dock" 1000 0 windowsize "$dock" 600 2600
  sleep 2
  xdotool mousemove 1599 2599
  sleep 1
  import -window root "$out/gui_full_pipeline_log.png"
  quit_gui
fi

# Inside the virtual display: a pocket remeshed alone (usage: --region-gui MESHLAB MESH OUT X Y Z).
if [ "${1:-}" = "--region-gui" ]; then
  start_gui "$2" "$3" "$4/region.meshlab.log"
  out=$4 cx=$5 cy=$6 cz=$7
  # The faces whose three corners lie within 8 A of the center (MeshLab's own selection filter):
  # its one text field sits under the help text, Apply at the bottom right.
  ball=
  for k in 0 1 2; do
    ball="$ball${ball:+ && }(x$k-($cx))^2+(y$k-($cy))^2+(z$k-($cz))^2<64"
  done
  open_dialog "Conditional Face Selection"
  xdotool mousemove $((WIDTH * 60 / 100)) $((HEIGHT - 124)) click --repeat 3 1
  xdotool key ctrl+a
  xdotool type --delay 5 "$ball"
  xdotool mousemove $((WIDTH * 74 / 100)) $((HEIGHT - 22)) click 1
  sleep 2
  xdotool mousemove $((WIDTH * 25 / 100)) $((HEIGHT - 22)) click 1 # Close
  sleep 1
  # Full Pipeline with "Remesh only selected faces" on: the last parameter, above the buttons.
  open_dialog "Molecular Remesh: Full Pipeline"
  xdotool mousemove 25 $((HEIGHT - 92)) click 1
  sleep 1
  import -window root "$out/gui_region_dialog.png"
  xdotool mousemove $((WIDTH * 74 / 100)) $((HEIGHT - 22)) click 1
  for _ in $(seq 1 300); do
    grep -q 'region remeshed' "$out/region.meshlab.log" && break
    sleep 1
  done
  sleep 6
  xdotool mousemove $((WIDTH * 25 / 100)) $((HEIGHT - 22)) click 1 # Close
  sleep 1
  # Wireframe on for the new layer (its row's wire toggle), trackball hidden, zoomed in twice.
  xdotool mousemove 1505 145 click 1
  sleep 1
  xdotool windowfocus --sync "$win" 2>/dev/null || true
  xdotool mousemove 600 530
  xdotool key --window "$win" shift+h
  for _ in 1 2; do
    xdotool click 5
    sleep 0.3
  done
  xdotool mousemove 1599 999
  sleep 2
  import -window root "$out/gui_region_remeshed.png"
  quit_gui
fi

repo=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-${BUILD_DIR:-$repo/build}}
cli=$build/cli/molremesh
data=${DATA_DIR:-$repo/../shared/data/meshes}
out=${OUT_DIR:-$repo/docs/images}
stages=${STAGES-}
zoom=${ZOOM:-2}
width=${WIDTH:-640}
read -r -a meshes <<<"${MESHES:-lysozyme_Lys1_msms ubiquitin_1UBQ_edtsurf_mc}"

for tool in meshlab xvfb-run xdotool import convert; do
  command -v "$tool" >/dev/null || {
    echo "make_pictures: '$tool' not found; install with: bash scripts/install_deps.sh --pictures" >&2
    exit 1
  }
done
[ -x "$cli" ] || { echo "make_pictures: $cli not built (cmake --build $build --target molremesh)" >&2; exit 1; }
server=$build/meshlabserver/run_meshlabserver.sh
plugin=$build/plugins/libfilter_molremesh.so
[ -x "$server" ] && [ -f "$plugin" ] || {
  echo "make_pictures: the plugin and its meshlabserver sandbox are not built (cmake --build $build" \
    "--target filter_molremesh meshlabserver_sandbox)" >&2
  exit 1
}
libdir=${MESHLAB_LIB_DIR:-$(sed -n 's/^export LD_LIBRARY_PATH="\([^$]*\)\$.*/\1/p' "$server")}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

# MeshLab's serialized MLRenderingData (see meshlabdocumentxml.cpp, MLPerViewGLOptions::serialize):
# 4 primitive bits (solid, wire triangles, wire edges, points), 9 attribute bits for each of points,
# wire edges, wire triangles, solid (position, vertex normal, face normal, vertex color, face
# color, vertex texture, wedge texture, 2 internal), then 32 view options (visible, single-side
# lighting, selection, fixed colors of box and wire only, wire unshaded).
glopts=10000000000100011010100000001000
faces_mode=1000$(printf '0%.0s' {1..27})101010000$glopts    # solid, flat, per-face color
vertices_mode=1000$(printf '0%.0s' {1..27})101100000$glopts # solid, flat, per-vertex color

capture() { # PLY MODE PNG
  local ply=$1 mode=$2 png=$3 project
  project=$work/$(basename "$png" .png).mlp
  cat >"$project" <<MLP
<!DOCTYPE MeshLabDocument>
<MeshLabProject>
 <MeshGroup>
  <MLMesh label="$(basename "$ply" .ply)" filename="$(basename "$ply")" visible="1">
   <MLMatrix44>
1 0 0 0 
0 1 0 0 
0 0 1 0 
0 0 0 1 
</MLMatrix44>
   <RenderingOption pointSize="3" wireWidth="1" boxColor="234 234 234 255" pointColor="131 149 69 255" wireColor="64 64 64 255" solidColor="192 192 192 255">$mode</RenderingOption>
  </MLMesh>
 </MeshGroup>
 <RasterGroup/>
</MeshLabProject>
MLP
  # xvfb-run -a can lose the race for a display number to another X server starting at the same
  # time ("could not connect to display"): try again a few times.
  local attempt
  for attempt in 1 2 3; do
    xvfb-run -a -s "-screen 0 1280x960x24" bash "$0" --capture "$project" "$work/raw.png" "$zoom" && break
    [ "$attempt" -lt 3 ] || { echo "make_pictures: MeshLab capture failed 3 times" >&2; exit 1; }
    echo "make_pictures: capture failed, retrying" >&2
    sleep 2
  done
  # The 3D view is the window below the menu and tool bars (y 70) above the status bar (34 px);
  # keep its middle 1000 px, where the mesh is centered.
  convert "$work/raw.png" -crop 1000x850+140+72 +repage -resize "${width}x" -strip \
    -define png:compression-level=9 "$png"
  echo "make_pictures: $png ($(du -k "$png" | cut -f1) KB)"
}

parts=${PARTS:-meshes gui region}
for mesh in "${meshes[@]}"; do
  [[ $parts == *meshes* ]] || break
  input=$data/$mesh.ply
  [ -f "$input" ] || { echo "make_pictures: $input not found" >&2; exit 1; }
  remeshed=$work/${mesh}_remeshed_raw.ply
  echo "make_pictures: molremesh remesh $mesh.ply (stages: ${stages:-all})"
  "$cli" remesh --verbose "$input" "$remeshed" ${stages:+--stages "$stages"} >"$work/$mesh.remesh.txt"
  for state in input remeshed; do
    source_ply=$input
    [ "$state" = remeshed ] && source_ply=$remeshed
    "$server" -i "$source_ply" -o "$work/${mesh}_$state.ply" -m vc fc vq fq \
      -s "$repo/meshlabserver_scripts/color_bad_elements.mlx" >"$work/$mesh.$state.color.txt" 2>&1
  done
  for state in input remeshed; do
    capture "$work/${mesh}_$state.ply" "$faces_mode" "$out/${mesh}_${state}_faces.png"
    capture "$work/${mesh}_$state.ply" "$vertices_mode" "$out/${mesh}_${state}_vertices.png"
  done
done

[[ $parts == *gui* || $parts == *region* ]] || exit 0
# The plugin in the GUI: a private copy of MeshLab whose plugins/ folder holds the system plugins
# and the build's (MeshLab looks for plugins beside its binary), on the first mesh.
gui=$work/gui
mkdir -p "$gui/plugins"
cp -f "$(command -v meshlab)" "$gui/meshlab"
for p in "$libdir"/plugins/*.so; do
  [ "$(basename "$p")" = "$(basename "$plugin")" ] || ln -sf "$p" "$gui/plugins/"
done
ln -sf "$(cd "$(dirname "$plugin")" && pwd)/$(basename "$plugin")" "$gui/plugins/"
cat >"$gui/run.sh" <<RUN
#!/usr/bin/env bash
export LD_LIBRARY_PATH="$libdir\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
exec "$gui/meshlab" "\$@"
RUN
chmod +x "$gui/run.sh"
if [[ $parts == *gui* ]]; then
  for attempt in 1 2 3; do
    xvfb-run -a -s "-screen 0 1600x2600x24" bash "$0" --gui "$gui/run.sh" "$data/${meshes[0]}.ply" "$work" && break
    [ "$attempt" -lt 3 ] || { echo "make_pictures: GUI capture failed 3 times" >&2; exit 1; }
    sleep 2
  done
  convert "$work/gui_color_bad_elements.png" -crop 1600x1000+0+0 +repage -resize 1000x -strip -define png:compression-level=9 \
    "$out/gui_color_bad_elements.png"
  convert "$work/gui_full_pipeline_dialog.png" -strip -define png:compression-level=9 "$out/gui_full_pipeline_dialog.png"
  # The floating layer dock: its layers (top), and the log with the tables (bottom).
  convert "$work/gui_full_pipeline_log.png" \( -clone 0 -crop 600x120+1000+0 \) \( -clone 0 -crop 600x${LOG_HEIGHT:-760}+1000+$((2600 - ${LOG_HEIGHT:-760})) \) \
    -delete 0 +repage -append -strip -define png:compression-level=9 "$out/gui_full_pipeline_log.png"
  for png in gui_color_bad_elements gui_full_pipeline_dialog gui_full_pipeline_log; do
    echo "make_pictures: $out/$png.png ($(du -k "$out/$png.png" | cut -f1) KB)"
  done
fi

[[ $parts == *region* ]] || exit 0
read -r cx cy cz <<<"${REGION_CENTER:-2.993 21.377 41.73}"
for attempt in 1 2 3; do
  xvfb-run -a -s "-screen 0 1600x1000x24" bash "$0" --region-gui "$gui/run.sh" "$data/${meshes[0]}.ply" "$work" \
    "$cx" "$cy" "$cz" && break
  [ "$attempt" -lt 3 ] || { echo "make_pictures: region capture failed 3 times" >&2; exit 1; }
  sleep 2
done
convert "$work/gui_region_dialog.png" -crop 1130x1000+0+0 +repage -resize 900x -strip -define png:compression-level=9 \
  "$out/gui_region_dialog.png"
convert "$work/gui_region_remeshed.png" -resize 1000x -strip -define png:compression-level=9 "$out/gui_region_remeshed.png"
for png in gui_region_dialog gui_region_remeshed; do
  echo "make_pictures: $out/$png.png ($(du -k "$out/$png.png" | cut -f1) KB)"
done
