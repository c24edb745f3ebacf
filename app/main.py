"""`volviz-app [SESSION|DATA]`: the desktop application. With no argument it opens the built-in demo scene."""
from __future__ import annotations

import argparse
import logging
import sys
import time
from typing import Optional, Sequence


def main(argv: Optional[Sequence[str]] = None) -> int:
    began = time.time()
    parser = argparse.ArgumentParser(prog="volviz-app", description="volviz desktop application")
    parser.add_argument("target", nargs="?", help="a session file (.json) or a data file; default: the demo scene")
    parser.add_argument("--screenshot", metavar="PNG", help="show the scene, save the window as PNG and quit (a check "
                        "that the app starts and renders)")
    parser.add_argument("--flight-report", metavar="MD", help="fly through the natural scene (default: the shipped "
                        "Yukon session) with W held, write the frame rate and the event loop's gaps to MD and quit")
    parser.add_argument("--flight-seconds", type=float, default=30.0, help="how long --flight-report flies (30)")
    parser.add_argument("--first-frame", action="store_true", help="open the target, print the time of its first "
                        "complete frame (seconds since the epoch and since main() began) and quit (volviz bench "
                        "startup)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")

    from PySide6.QtWidgets import QApplication

    from .window import MainWindow

    existing = QApplication.instance()  # reused when it is a QApplication (a QCoreApplication shows no windows)
    app = existing if isinstance(existing, QApplication) else QApplication(sys.argv[:1])
    app.setApplicationName("volviz")
    app.setOrganizationName("volviz")
    app.setWindowIcon(_icon())
    if args.screenshot or args.flight_report or args.first_frame:  # a throwaway window: the user's settings and
        import tempfile                                             # recovery files stay untouched
        from pathlib import Path

        from PySide6.QtCore import QSettings

        scratch = Path(tempfile.mkdtemp(prefix="volviz-app-check-"))
        window = MainWindow(settings=QSettings(str(scratch / "settings.ini"), QSettings.Format.IniFormat),
                            recovery_dir=scratch / "recovery")
        if args.flight_report:
            from .flight_report import flight_report

            return flight_report(app, window, args.target, Path(args.flight_report), args.flight_seconds)
        from .smoke import screenshot

        if args.first_frame:
            return _first_frame(app, window, args.target, began)
        return screenshot(app, window, args.target, Path(args.screenshot))
    window = MainWindow()
    window.show()
    if args.target:
        window.open_path(args.target)
    else:
        window.open_demo()
    window.offer_recovery()
    return int(app.exec())


def _first_frame(app, window, target: Optional[str], began: float) -> int:
    """Show ``target`` (None: the demo) and print when its first complete frame is drawn, as ``--screenshot`` waits
    for it: ``first frame <epoch seconds> <seconds since main() began>`` (``volviz bench startup``, issue #31)."""
    from .smoke import show_target

    shown = show_target(app, window, target)
    window.plotter.render()
    now = time.time()
    print(f"first frame {now:.3f} {now - began:.3f}", flush=True)
    window.dirty = False
    window.close()
    return 0 if shown and window.error_dialog is None else 1


def _icon():
    from importlib import resources

    from PySide6.QtGui import QIcon

    return QIcon(str(resources.files("volviz_resources") / "icons" / "volviz.svg"))


if __name__ == "__main__":
    sys.exit(main())
