#!/bin/bash
# On the GPU machine (see build-kit.sh): unpack the GL loaders and the kit, then volviz bench unstructured at
# 512², 1920x1080 and 3840x2160 with VTK's peers in the same run; the report and log land under $OUT (issue #29).
set -u
T0=$(date +%s)
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
VENDOR=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f $VENDOR ] || VENDOR=$(ls /usr/share/glvnd/egl_vendor.d/*nvidia*.json /usr/local/nvidia/share/glvnd/egl_vendor.d/*.json 2>/dev/null | head -1)
export __EGL_VENDOR_LIBRARY_FILENAMES=$VENDOR
mkdir -p /tmp/site /tmp/shim && tar -C /tmp/site -xJf .gpu/kit.tar.xz
mkdir -p /tmp/src && tar -C /tmp/src -xJf .gpu/src.tar.xz; SRC=/tmp/src; ln -sfn $SRC/resources /tmp/shim/volviz_resources
export PYTHONPATH=/tmp/shim:$SRC:/tmp/site PYTHONUNBUFFERED=1 VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
export NUMBA_CACHE_DIR=/tmp/numba
{ echo "vendor $VENDOR"; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc;
  python3 -c "import sys, numba, numpy; print(sys.version.split()[0], 'numba', numba.__version__, 'numpy', numpy.__version__)"; } > $OUT/env.txt 2>&1
echo "setup $(( $(date +%s) - T0 )) s" >> $OUT/env.txt
python3 - >> $OUT/env.txt 2>&1 <<'PY'
import pyvista as pv
pl = pv.Plotter(off_screen=True, window_size=[64, 64]); pl.add_mesh(pv.Sphere()); pl.render()
caps = pl.ren_win.ReportCapabilities()
print(type(pl.ren_win).__name__, [l for l in caps.splitlines() if "renderer string" in l or "version string" in l])
PY
cat $OUT/env.txt
mkdir -p $OUT/h200
timeout ${BENCH_TIMEOUT:-400} python3 -c "import sys; from volviz.cli import main; sys.exit(main())" bench unstructured \
  --dataset .gpu/data/bluntfin --size 512 --frames 4 --reps 5 --vtk vtkProjectedTetrahedraMapper \
  --scan 512,1920x1080,3840x2160 --scan-reps 5 --raycast-grid 160 \
  --cpu-sizes 512,1920x1080,3840x2160 --interactive-sizes 1920x1080,3840x2160 \
  --sort-sizes 256,512,1920x1080,3840x2160 --large-refine 2.3 \
  --out $OUT/h200 --json $OUT/h200/unstructured.json 2>&1 | grep -v "bad X server" | tee $OUT/bench.log
echo "total $(( $(date +%s) - T0 )) s"
