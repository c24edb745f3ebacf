#!/usr/bin/env bash
# Every install the README documents works (issue #32): volviz alone, each extra alone, each extra with every plugin
# in plugins/, and all extras with every plugin -- each in a fresh virtual environment made with uv (its cache
# hard-links the packages, so each environment after the first takes seconds), where packaging/check_install.py
# imports every reader and each extra's modules and opens one file of each plugin format (the shared data's
# ecosystem files, else files written with the formats' own libraries). The bench extra beside the imaging plugin
# once broke every `import zarr`; no test installed both.
#
#   bash packaging/check-installs.sh [INSTALL ...]      (default: all; names as printed, e.g. bench+plugins)
#
# Environment: PYTHON (default .venv/bin/python, with uv installed: `pip install uv`), VOLVIZ_DATA (default
# ../shared/data), CHECK_INSTALLS_DIR (where the environments go; default a temporary folder, removed after).
# Exit status 1 when any install fails; one summary line per install, its log kept on failure.
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-.venv/bin/python}
DATA=${VOLVIZ_DATA:-$(cd .. && pwd)/shared/data}
EXTRAS=(movies bench cluster console packaging test)
ALL=$(IFS=,; echo "${EXTRAS[*]}")
PLUGINS=()
for plugin in plugins/*/pyproject.toml; do
  PLUGINS+=(-e "$(dirname "$plugin")")
done

if ! "$PYTHON" -m uv --version >/dev/null 2>&1; then
  echo "check-installs: uv is not installed in $PYTHON's environment (run: $PYTHON -m pip install uv)" >&2
  exit 2
fi
[ -d "$DATA/ecosystem" ] || { echo "check-installs: no ecosystem folder in $DATA (set VOLVIZ_DATA)" >&2; exit 2; }
BASE=$("$PYTHON" -c 'import sys; print(sys._base_executable)')
WORK=${CHECK_INSTALLS_DIR:-}
if [ -z "$WORK" ]; then
  WORK=$(mktemp -d -t volviz-check-installs-XXXXXX)
  trap 'rm -rf "$WORK"' EXIT
fi

# name, then the requirement of volviz, then "plugins" when every plugin goes with it
declare -a NAMES SPECS WITH
add() { NAMES+=("$1"); SPECS+=("$2"); WITH+=("$3"); }
add base "." ""
for extra in "${EXTRAS[@]}"; do
  add "$extra" ".[$extra]" ""
  add "$extra+plugins" ".[$extra]" plugins
done
add "all+plugins" ".[$ALL]" plugins

wanted=("$@")
failed=0
start=$(date +%s)
for i in "${!NAMES[@]}"; do
  name=${NAMES[$i]}
  if [ ${#wanted[@]} -gt 0 ] && [[ ! " ${wanted[*]} " == *" $name "* ]]; then
    continue
  fi
  t0=$(date +%s)
  env="$WORK/$name"
  log="$WORK/$name.log"
  extras=""
  [[ ${SPECS[$i]} == *"["* ]] && extras=$(echo "${SPECS[$i]}" | sed 's/.*\[\(.*\)\]/\1/; s/,/ /g')
  args=(-e "${SPECS[$i]}")
  [ "${WITH[$i]}" = plugins ] && args+=("${PLUGINS[@]}")
  if "$PYTHON" -m uv venv -q --python "$BASE" "$env" >"$log" 2>&1 &&
      "$PYTHON" -m uv pip install -q --python "$env/bin/python" "${args[@]}" >>"$log" 2>&1 &&
      "$env/bin/python" packaging/check_install.py "$DATA" $extras >>"$log" 2>&1; then
    echo "ok     $name ($(( $(date +%s) - t0 )) s): $(tail -n 1 "$log")"
    rm -rf "$env"
  else
    failed=1
    echo "FAILED $name ($(( $(date +%s) - t0 )) s): $(grep -m 3 -E '^FAILED|error' "$log" | tr '\n' ' ')(log: $log)"
    trap - EXIT   # keep the environment and its log to look at
  fi
done
echo "check-installs: $(( $(date +%s) - start )) s"
exit $failed
