"""`volviz-app [SESSION|DATA]`: the desktop application. With no argument it opens the built-in demo scene."""
from __future__ import annotations

import argparse
import logging
import sys
from typing import Optional, Sequence


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="volviz-app", description="volviz desktop application")
    parser.add_argument("target", nargs="?", help="a session file (.json) or a data file; default: the demo scene")
    parser.add_argument("--screenshot", metavar="PNG", help="show the scene, save the window as PNG and quit (a check "
                        "that the app starts and renders)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")

    from PySide6.QtWidgets import QApplication

    from .window import MainWindow

    existing = QApplication.instance()  # reused when it is a QApplication (a QCoreApplication shows no windows)
    app = existing if isinstance(existing, QApplication) else QApplication(sys.argv[:1])
    app.setApplicationName("volviz")
    app.setOrganizationName("volviz")
    app.setWindowIcon(_icon())
    if args.screenshot:  # a throwaway window: the user's settings and recovery files stay untouched
        import tempfile
        from pathlib import Path

        from PySide6.QtCore import QSettings

        from .smoke import screenshot

        scratch = Path(tempfile.mkdtemp(prefix="volviz-app-check-"))
        window = MainWindow(settings=QSettings(str(scratch / "settings.ini"), QSettings.Format.IniFormat),
                            recovery_dir=scratch / "recovery")
        return screenshot(app, window, args.target, Path(args.screenshot))
    window = MainWindow()
    window.show()
    if args.target:
        window.open_path(args.target)
    else:
        window.open_demo()
    window.offer_recovery()
    return int(app.exec())


def _icon():
    from importlib import resources

    from PySide6.QtGui import QIcon

    return QIcon(str(resources.files("volviz_resources") / "icons" / "volviz.svg"))


if __name__ == "__main__":
    sys.exit(main())
