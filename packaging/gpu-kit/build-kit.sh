#!/bin/bash
# Build the kit that carries volviz's GPU benchmarks to a lent GPU machine (Python 3.12, no network, 64 MiB per call;
# DESIGN notes "What an NVIDIA GPU showed"). Run from the repository root; writes the git-ignored .gpu/ and .gl/:
#   .gpu/kit.tar.xz   the vtkmodules shared objects a bench run loads (from /proc/self/maps), VTK's Python files,
#                     pyvista, pydantic and their pure dependencies missing from the machine's image, stripped, xz -9e
#   .gpu/src.tar.xz   volviz and its resources at HEAD (plus the working tree's volviz/bench/unstructured.py)
#   .gpu/data/        the Blunt Fin;  .gl/*.deb  glvnd's GL loaders (libEGL, libOpenGL, ...) to unpack there
# Then: the device tool's run with carry [".gl", ".gpu"] and command `bash .gpu/run.sh` (results under $OUT).
set -eu
PY312=${PY312:-$HOME/.pyenv/versions/3.12.1/bin/python}
KIT=${KIT:-/tmp/volviz-gpu-kit}
mkdir -p "$KIT" .gpu/data/bluntfin .gl
[ -x "$KIT/venv/bin/python" ] || "$PY312" -m venv "$KIT/venv"
"$KIT/venv/bin/pip" install -q "numpy==2.4.6" scipy "numba==0.68.1" h5py pillow matplotlib "vtk==9.7.2" \
    "pyvista==0.49.1" "pydantic==2.14.4" meshio tifffile
mkdir -p "$KIT/shim" && ln -sfn "$PWD/resources" "$KIT/shim/volviz_resources"
# one small run of the same bench records what it loads
CAPTURE_OUT="$KIT/maps.txt" PYTHONPATH="$KIT/shim:$PWD" "$KIT/venv/bin/python" packaging/gpu-kit/capture.py \
    bench unstructured --size 32 --frames 2 --reps 1 --vtk vtkProjectedTetrahedraMapper --scan 32,48x32 \
    --raycast-grid 20 --exact 48x32 --cpu-sizes 32,48x32 --interactive-sizes 48x32 --sort-sizes 32 \
    --large-refine 1.1 --no-compare-3d --out "$KIT/bench" > "$KIT/capture.log" 2>&1
SP=$("$KIT/venv/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")
rm -rf "$KIT/site" && mkdir "$KIT/site"
for p in pyvista pyvista_validation scooby pooch platformdirs pydantic pydantic_core annotated_types typing_inspection; do
    cp -r "$SP/$p" "$KIT/site/"
done
(cd "$SP" && find vtkmodules -name "*.py" | grep -v "/web/\|/test" | xargs -I{} cp --parents {} "$KIT/site/")
grep "site-packages/vtkmodules/" "$KIT/maps.txt" | xargs -I{} cp {} "$KIT/site/vtkmodules/"
find "$KIT/site" -name __pycache__ -prune -exec rm -rf {} +
strip --strip-unneeded "$KIT/site/vtkmodules/"*.so "$KIT/site/pydantic_core/"*.so
tar -C "$KIT/site" -cf - . | xz -9e -T2 > .gpu/kit.tar.xz
rm -rf "$KIT/src" && mkdir -p "$KIT/src" && git archive HEAD volviz resources | tar -x -C "$KIT/src"
cp volviz/bench/unstructured.py "$KIT/src/volviz/bench/"
tar -C "$KIT/src" -cf - . | xz -9 > .gpu/src.tar.xz
cp ../shared/data/bluntfin/*.bin .gpu/data/bluntfin/
cp packaging/gpu-kit/run.sh .gpu/run.sh
o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
mkdir -p /tmp/amd64/partial && apt-get $o update > /dev/null
(cd .gl && apt-get $o download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
du -cb .gpu .gl $(git ls-files) | tail -1   # with the tracked files, what one call carries: under 64 MiB
