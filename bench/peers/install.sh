#!/usr/bin/env bash
# Install the peer programs of the side-by-side benchmark into places git ignores:
#   CalculiX ccx 2.20 from Debian (system package), OpenSees 3.7.1 (openseespy 3.7.1.2) and
#   OOFEM 2.6.0.dev1 from PyPI into bench/peers/.venv (and matplotlib for the figures). Needs root for apt-get (as on the
#   project's machines). Idempotent: skips what is already there.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv"

if ! command -v ccx >/dev/null 2>&1 || ! [ -e /usr/lib/x86_64-linux-gnu/libblas.so.3 ]; then
    apt-get update -qq
    # libblas3/liblapack3: openseespylinux loads libblas.so.3 and liblapack.so.3 from the system.
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq calculix-ccx libblas3 liblapack3 time >/dev/null
fi

if ! [ -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
if ! "$venv/bin/python" -c 'import openseespy.opensees, oofem' >/dev/null 2>&1; then
    "$venv/bin/pip" install -q numpy 'openseespy==3.7.1.2'
    # The oofem wheel's metadata also asks for pytest, which it does not need to run.
    "$venv/bin/pip" install -q --pre --no-deps 'oofem==2.6.0.dev1'
fi
# matplotlib: the figures of bench/peers/scaling.py.
"$venv/bin/python" -c 'import matplotlib' >/dev/null 2>&1 || "$venv/bin/pip" install -q matplotlib
"$venv/bin/python" -c 'import openseespy.opensees, oofem; print("peers: OpenSees and OOFEM import")'
command -v ccx >/dev/null && echo "peers: $(ccx -v 2>/dev/null | grep -i version | head -1)"
