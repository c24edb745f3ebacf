#!/usr/bin/env bash
# Build the one-folder app with PyInstaller (dist/volviz/volviz-app) and check that it starts and renders the demo
# scene, a VTK file and a NIfTI file: the built app opens each under Xvfb, saves its window as PNG and quits; the PNG
# must show the scene.
# Run after packaging/setup-debian.sh:  bash packaging/build-app.sh [DIST_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
dist="${1:-dist}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# (CI installs the extra before its tests start, so pip does not rewrite the environment while they run)
[ "${VOLVIZ_PACKAGING_INSTALLED:-0}" = 1 ] || .venv/bin/python -m pip install -q -e ".[packaging]"
# the build and the warm-up are batch work, run at low priority: beside other work they take the CPU it leaves (CI runs
# them beside the tests, whose event-loop checks measure the app's latency)
nice -n 10 .venv/bin/pyinstaller --noconfirm --log-level WARN --distpath "$dist" --workpath "$work/build" packaging/volviz.spec
app="$(cd "$dist/volviz" && pwd)/volviz-app"
echo "built $app ($(du -sh "$dist/volviz" | cut -f1))"
# the install step: compile the Numba kernels into their on-disk cache, as the setup script's `volviz warmup` does for a
# development install (without it the first start compiles the demo's kernels: about 65 s of CPU)
(cd "$work" && env -u VIRTUAL_ENV PATH=/usr/bin:/bin nice -n 10 "$app" -m volviz warmup)
# a small VTK XML volume: its reader runs in the isolated reader process, which the packaged app starts as itself
.venv/bin/python -c "import pyvista as pv, numpy as np; g = pv.ImageData(dimensions=(24, 24, 24)); \
x = np.linspace(-1, 1, 24); X, Y, Z = np.meshgrid(x, x, x, indexing='ij'); \
g.point_data['density'] = np.exp(-4 * (X**2 + Y**2 + Z**2)).ravel(order='F'); g.save('$work/blob.vti')"
# and the same blob as NIfTI (the volviz-imaging plugin: nibabel, found through its entry point)
.venv/bin/python -c "import nibabel as nib, numpy as np; x = np.linspace(-1, 1, 24); \
X, Y, Z = np.meshgrid(x, x, x, indexing='ij'); \
nib.save(nib.Nifti1Image((1000 * np.exp(-4 * (X**2 + Y**2 + Z**2))).astype(np.int16), np.eye(4)), '$work/blob.nii.gz')"
# the checks run from another folder, with no virtual environment on PATH: only what was packaged is used
for target in demo "$work/blob.vti" "$work/blob.nii.gz"; do
    (cd "$work" && env -u VIRTUAL_ENV PATH=/usr/bin:/bin xvfb-run -a -s "-screen 0 1280x900x24" \
        "$app" --screenshot "$work/check.png" $([ "$target" = demo ] || echo "$target"))
    .venv/bin/python - "$work/check.png" "$target" <<'PY'
import sys

import numpy as np
from PIL import Image

rgb = np.asarray(Image.open(sys.argv[1]).convert("RGB"), dtype=float)
spread = rgb.reshape(-1, 3).std(axis=0).mean()
print(f"the packaged app showed {sys.argv[2]}: {rgb.shape[1]}x{rgb.shape[0]} window, color spread {spread:.1f}")
sys.exit(0 if spread > 10 else "the packaged app's window is blank")
PY
done
