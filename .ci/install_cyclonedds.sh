#!/usr/bin/env bash
# Build the cyclonedds Python binding 0.10.2 (the version the G1 firmware and Unitree's SDK
# speak; 11.x does not interoperate, see /work/shared/reference/g1.md) against Debian's
# cyclonedds-dev. Idempotent: does nothing when 0.10.2 is already importable.
#
# 0.10.2 ships no wheel and its setup.py looks for the C library under CYCLONEDDS_HOME/lib,
# while Debian puts it in the multiarch dir, so we give it a prefix made of symlinks.
set -euo pipefail

PY="${PYTHON:-python}"
PREFIX="${CYCLONEDDS_PREFIX:-/opt/cyclonedds-prefix}"
WANT="0.10.2"

# 0.10.2 exposes no cyclonedds.__version__; the installed distribution's metadata is the
# reliable source, and importing cyclonedds.domain proves the C extension loads.
if "$PY" - <<PYEOF 2>/dev/null
import importlib.metadata, cyclonedds.domain
assert importlib.metadata.version("cyclonedds") == "$WANT"
PYEOF
then
    echo "cyclonedds $WANT already installed"
    exit 0
fi

if ! dpkg -s cyclonedds-dev >/dev/null 2>&1 || [ ! -x /usr/bin/idlc ]; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update
    $SUDO apt-get install -y cyclonedds-dev cyclonedds-tools
fi

MULTIARCH="$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || echo x86_64-linux-gnu)"
mkdir -p "$PREFIX/lib" "$PREFIX/bin"
for so in /usr/lib/"$MULTIARCH"/libddsc.so*; do
    ln -sfn "$so" "$PREFIX/lib/$(basename "$so")"
done
ln -sfn /usr/include "$PREFIX/include"
ln -sfn /usr/bin/idlc "$PREFIX/bin/idlc"

# --no-build-isolation is not used: setup.py needs only setuptools/wheel, which pip provides.
CYCLONEDDS_HOME="$PREFIX" "$PY" -m pip install "cyclonedds==$WANT"

"$PY" - <<PYEOF
import importlib.metadata, cyclonedds.domain
v = importlib.metadata.version("cyclonedds")
assert v == "$WANT", v
print("cyclonedds", v, "ok")
PYEOF
