#!/usr/bin/env bash
# Fetches and unpacks Debian's source package of the installed MeshLab (plugin headers + vcglib)
# into DEST, using a private deb-src list and private apt state: the system's apt configuration
# is never modified. Idempotent: an existing unpacked tree is reused.
#
# usage: fetch_meshlab_source.sh DEST
set -euo pipefail

dest=${1:?usage: fetch_meshlab_source.sh DEST}
mkdir -p "$dest"
dest=$(cd "$dest" && pwd)
stamp="$dest/.unpacked"

version=$(dpkg-query -W -f='${Version}' meshlab 2>/dev/null || true)
if [ -z "$version" ]; then
  echo "fetch_meshlab_source: the Debian package 'meshlab' is not installed" >&2
  exit 1
fi
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$version" ]; then
  exit 0
fi

# The archive that serves the installed meshlab binary package serves its source too:
# take its address and suite from apt's own policy output (e.g. "500 http://deb.debian.org/debian bookworm/main ...").
read -r uri suite_component < <(apt-cache policy meshlab |
  awk '/^ \*\*\*/ {found=1; next} found && $2 ~ /^https?:/ {print $2, $3; exit}')
if [ -z "${uri:-}" ]; then
  echo "fetch_meshlab_source: cannot find the archive that provides meshlab $version" >&2
  exit 1
fi
suite=${suite_component%%/*}
component=${suite_component#*/}
keyring=/usr/share/keyrings/debian-archive-keyring.gpg

apt_dir="$dest/apt"
mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial" "$apt_dir/sources.list.d"
cat >"$apt_dir/sources.list" <<LIST
deb-src [signed-by=$keyring] $uri $suite $component
LIST
apt_opts=(
  -o "APT::Sandbox::User=root"
  -o "Dir::Etc::SourceList=$apt_dir/sources.list"
  -o "Dir::Etc::SourceParts=$apt_dir/sources.list.d"
  -o "Dir::State::Lists=$apt_dir/lists"
  -o "Dir::Cache=$apt_dir/cache"
  -o "APT::Get::List-Cleanup=0"
)
echo "fetch_meshlab_source: fetching meshlab=$version source from $uri $suite/$component"
apt-get "${apt_opts[@]}" -q update >"$apt_dir/update.log" 2>&1 ||
  { cat "$apt_dir/update.log" >&2; exit 1; }
work="$dest/download"
rm -rf "$work" && mkdir -p "$work"
(cd "$work" && apt-get "${apt_opts[@]}" -q source --download-only "meshlab=$version")

dsc=$(ls "$work"/meshlab_*.dsc | head -n1)
rm -rf "$dest/meshlab"
dpkg-source --no-check -x "$dsc" "$dest/meshlab" >/dev/null
echo "$version" >"$stamp"
echo "fetch_meshlab_source: unpacked into $dest/meshlab"
