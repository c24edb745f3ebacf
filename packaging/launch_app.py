"""The entry script of the packaged app (PyInstaller, ``packaging/volviz.spec``).

A frozen app has no Python interpreter to run a module with, so the app's own executable stands in for one:
``volviz-app -m volviz.io.isolated`` is the reader child (``sys.executable`` is the app there), ``volviz-app -m volviz
ARGS`` is volviz's command line (``volviz-app -m volviz warmup`` compiles the kernels at install, as the setup script
does for a development install), and every other call starts the application. ``freeze_support`` lets the warm-up's
worker processes (``spawn``) start as the app too.
"""
import multiprocessing
import sys

if __name__ == "__main__":
    multiprocessing.freeze_support()
    if sys.argv[1:3] == ["-m", "volviz.io.isolated"]:
        from volviz.io.isolated.__main__ import main as reader_child

        sys.argv = [sys.argv[0], *sys.argv[3:]]
        sys.exit(reader_child())
    if sys.argv[1:3] == ["-m", "volviz"]:
        from volviz.cli import main as command_line

        sys.exit(command_line(sys.argv[3:]))
    from volviz_app.main import main

    sys.exit(main())
