#!/usr/bin/env bash
# usage: run.sh START END TAG   -- generate and diagnose seeds START..END into ${PROBE_OUT:-/tmp/p}/TAG/SEED/ (2 at a time)
# env: CODE (code snapshot to test, default this checkout), PY, JOBS (default 2), PROBE_OVERRIDE (checks only)
set -u
START=$1; END=$2; TAG=$3
export PY=${PY:-$(cd "$(dirname "$0")/../.." && pwd)/.venv/bin/python}
export CODE=${CODE:-$(cd "$(dirname "$0")/../.." && pwd)}
export PROBE=$(cd "$(dirname "$0")" && pwd)
export BASE=${PROBE_OUT:-/tmp/p}/$TAG
mkdir -p "$BASE"
one() {
  seed=$1; d=$BASE/$seed
  rm -rf "$d"; mkdir -p "$d"
  "$PY" "$PROBE/gen.py" "$seed" "$d" >"$d/gen.out" 2>"$d/gen.err"; echo $? >"$d/gen.rc"
  if [ -f "$d/skip.json" ] || [ "$(cat "$d/gen.rc")" != 0 ]; then echo "seed $seed: generator skip/error"; return 0; fi
  model=$("$PY" -c "import json,sys;print(json.load(open(sys.argv[1]))['aircraft'])" "$d/truth.json")
  t0=$(date +%s.%N)
  (cd "$CODE" && PYTHONPATH="$CODE" timeout 900 "$PY" -m harness diagnose --model "$model" \
      --recording "$d/id.csv" --validation "$d/val.csv" --out "$d/diag" --workers 1) \
      >"$d/diag.out" 2>"$d/diag.err"
  echo $? >"$d/diag.rc"
  echo "$(date +%s.%N) - $t0" | bc >"$d/diag.seconds"
  echo "seed $seed: diagnose exit $(cat "$d/diag.rc") ($(cat "$d/diag.seconds") s)"
}
export -f one
seq "$START" "$END" | xargs -P "${JOBS:-2}" -I{} bash -c 'one {}'
