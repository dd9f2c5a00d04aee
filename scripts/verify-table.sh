#!/bin/sh
# Runs `varia verify` on every scene under scenes/ (scenes/bad/ excepted, those are refused by
# design) and prints a Markdown table: per property the prediction, the measurement and whether it
# holds ("yes", "no", "-" when nothing is predicted), then verify's exit code. docs/verify.md's
# tables are this script's output: with no scenes named, every scene under scenes/; docs/audit/*.json
# for the audit's compositions. Usage: scripts/verify-table.sh [VARIA [SCENE...]]
set -eu
cd "$(dirname "$0")/.."
varia=${1:-build/bin/varia}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- scenes/*.json scenes/*/*.json
properties="self_adjoint g_invariant ld_order global_order momentum_conserved symplectic energy_bounded"
printf '| scene |'
for p in $properties; do printf ' %s |' "$p"; done
printf ' exit |\n|---|'
for p in $properties; do printf -- '---|'; done
printf -- '---|\n'
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
for scene; do
  case "$scene" in scenes/bad/*) continue ;; esac
  status=0
  "$varia" verify "$scene" >"$tmp" 2>/dev/null || status=$?
  name=${scene#scenes/}
  printf '| `%s` |' "${name#docs/audit/}"
  for p in $properties; do
    # Columns of verify's table: property predicted measured tolerance holds how...
    cell=$(awk -v p="$p" '$1 == p { printf "%s / %s %s", $2, $3, $5; exit }' "$tmp")
    printf ' %s |' "${cell:--}"
  done
  printf ' %s |\n' "$status"
done
