#!/usr/bin/env bash
# Install the peer programs of the side-by-side benchmark into places git ignores:
#   CalculiX ccx 2.20 from Debian (system package), OpenSees 3.7.1 (openseespy 3.7.1.2) and
#   OOFEM 2.6.0.dev1 from PyPI into bench/peers/.venv (and matplotlib for the figures). Needs root for apt-get (as on the
#   project's machines). Idempotent: skips what is already there.
# Peers at their best (issue 43 item 1): openseespy loads BLAS from the system's libblas.so.3
#   (its LAPACK is a copy in the wheel, found first by its RPATH, which calls that BLAS);
#   Debian's OpenBLAS (libopenblas0-pthread) registers libblas.so.3 through
#   update-alternatives at a higher priority than the reference BLAS, so OpenSees runs
#   on OpenBLAS (1.4-1.7x faster with UmfPack than on the reference BLAS). peers.py sets
#   OPENBLAS_NUM_THREADS per run mode (one core / all cores). taskset (util-linux) pins the
#   one-core runs.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv"

openblas=/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3
if ! command -v ccx >/dev/null 2>&1 || ! [ -e "$openblas" ] || ! command -v taskset >/dev/null 2>&1; then
    apt-get update -qq
    # libblas3/liblapack3: openseespylinux loads libblas.so.3 and liblapack.so.3 from the system.
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq calculix-ccx libblas3 liblapack3 \
        libopenblas0-pthread util-linux time >/dev/null
fi
# OpenBLAS as the system's BLAS and LAPACK (the alternatives' automatic choice; set it in case
# an administrator pinned the reference BLAS).
update-alternatives --set libblas.so.3-x86_64-linux-gnu "$openblas" >/dev/null
update-alternatives --set liblapack.so.3-x86_64-linux-gnu \
    /usr/lib/x86_64-linux-gnu/openblas-pthread/liblapack.so.3 >/dev/null

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
echo "peers: BLAS $(readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3), LAPACK $(readlink -f /usr/lib/x86_64-linux-gnu/liblapack.so.3)"
