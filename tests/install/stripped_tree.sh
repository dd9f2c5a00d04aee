#!/usr/bin/env bash
# The installed, stripped tree end to end (docs/security.md, "Only the plugins a scene names are
# loaded"): `cmake --install --strip` into a temporary prefix; its plugins then have no .symtab, only
# the dynamic symbol table. The installed varia must list every installed plugin, and run a bundled
# scene loading only the plugin files that scene names (the type marker read from .dynsym), as the
# dynamic loader reports (LD_DEBUG=files) and the run record says (plugins_loaded).
# Usage: stripped_tree.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "stripped tree: $*" >&2; exit 1; }
cmake --install "$build" --prefix "$work/prefix" --strip >/dev/null
varia=$work/prefix/bin/varia
plugins=$work/prefix/lib/varia/plugins
installed=$(find "$plugins" -name '*.so' | wc -l)
[ "$installed" -gt 3 ] || fail "only $installed plugins installed in $plugins"
for file in "$varia" "$plugins"/*.so; do
  if readelf -S -W "$file" | grep -q '\.symtab'; then fail "$file is not stripped (it has a .symtab)"; fi
done

# Listed: every installed file, none refused.
listed=$("$varia" plugins --json | jq length)
[ "$listed" -eq "$installed" ] || fail "varia plugins --json lists $listed plugins of the $installed installed"

# The scene schema and the example scenes that --help names, installed: every scene valid.
share=$work/prefix/share/varia
jq -e '.type == "object"' "$share/scene.schema.json" >/dev/null || fail "no scene schema in $share"
"$varia" --help | grep -q "share/varia/scenes/" || fail "varia --help does not name the installed scenes"
scenes=0
while IFS= read -r -d '' scene; do
  "$varia" validate "$scene" >/dev/null || fail "the installed scene $scene is not valid"
  scenes=$((scenes + 1))
done < <(find "$share/scenes" -name '*.json' -print0)
[ "$scenes" -gt 20 ] || fail "only $scenes example scenes installed in $share/scenes"
[ ! -e "$share/scenes/bad" ] || fail "the refused scenes of scenes/bad are installed"

# Run: only the files the scene names are opened.
LD_DEBUG=files LD_DEBUG_OUTPUT="$work/ld" "$varia" run "$share/scenes/default.json" --quiet \
  --summary "$work/run.json" --out "$work/run.csv"
opened=$(cat "$work"/ld.* | grep -o "file=$plugins/[^ ]*\.so \[0\];  dynamically loaded" | sort -u | wc -l)
named=$(jq '.plugins_loaded | length' "$work/run.json")
[ "$named" -ge 1 ] || fail "the run record names no plugin loaded"
[ "$opened" -eq "$named" ] || fail "the run opened $opened plugin files of $installed for the $named it needs: $(jq -c .plugins_loaded "$work/run.json")"
[ "$(wc -l <"$work/run.csv")" -eq 202 ] || fail "the trajectory has $(wc -l <"$work/run.csv") lines, not 202"
# The Python module, installed beside them: it finds the installed plugins and runs the scene.
PYTHONPATH=$work/prefix/lib/python3/dist-packages /usr/bin/python3 -c "
import varia
assert len(varia.plugins()) == $installed, 'the installed module lists another set of plugins'
assert len(varia.run('$share/scenes/default.json').t) == 201
" || fail "the installed Python module does not list the installed plugins or run the default scene"

echo "stripped tree: $installed plugins installed and listed, $scenes example scenes valid; the default scene opened $opened ($(jq -c .plugins_loaded "$work/run.json"))"
