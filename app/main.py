"""`volviz-app [SESSION|DATA]`: the desktop application. With no argument it opens the built-in demo scene."""
from __future__ import annotations

import argparse
import logging
import sys
from typing import Optional, Sequence


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="volviz-app", description="volviz desktop application")
    parser.add_argument("target", nargs="?", help="a session file (.json) or a data file; default: the demo scene")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")

    from PySide6.QtWidgets import QApplication

    from volviz_app.window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("volviz")
    app.setOrganizationName("volviz")
    window = MainWindow()
    window.show()
    if args.target:
        window.open_path(args.target)
    else:
        window.open_demo()
    window.offer_recovery()
    return int(app.exec())


if __name__ == "__main__":
    sys.exit(main())
