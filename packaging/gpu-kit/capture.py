"""Run ``volviz ARGS`` and, at its exit, write what the run loaded, which is what the GPU kit must carry: the shared
objects mapped (``$CAPTURE_OUT``), the VTK Python modules (``.mods``) and the top-level packages (``.top``)."""
import atexit
import os
import sys


def dump() -> None:
    libs = set()
    with open("/proc/self/maps") as maps:
        for line in maps:
            parts = line.split()
            if len(parts) >= 6 and ".so" in parts[5]:
                libs.add(parts[5])
    out = os.environ["CAPTURE_OUT"]
    with open(out, "w") as f:
        f.write("\n".join(sorted(libs)) + "\n")
    with open(out + ".mods", "w") as f:
        f.write("\n".join(sorted(m for m in sys.modules if m.startswith("vtkmodules"))) + "\n")
    with open(out + ".top", "w") as f:
        f.write("\n".join(sorted({m.split(".")[0] for m in sys.modules})) + "\n")


if __name__ == "__main__":
    atexit.register(dump)
    from volviz.cli import main

    sys.argv = ["volviz", *sys.argv[1:]]
    try:
        main()
    except SystemExit:
        pass
