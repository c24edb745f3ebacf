"""The entry script of the packaged app (PyInstaller, ``packaging/volviz.spec``).

A frozen app has no Python interpreter to start ``python -m volviz.io.isolated`` with, so the reader child is the
app's own executable called as ``volviz-app -m volviz.io.isolated`` (``sys.executable`` is the app there); every
other call starts the application.
"""
import sys

if __name__ == "__main__":
    if sys.argv[1:3] == ["-m", "volviz.io.isolated"]:
        from volviz.io.isolated.__main__ import main as reader_child

        sys.argv = [sys.argv[0], *sys.argv[3:]]
        sys.exit(reader_child())
    from volviz_app.main import main

    sys.exit(main())
