"""View > Python Console: an IPython console dock running in the app's own process (qtconsole's in-process kernel),
with ``window``, ``session`` (the shown session model, updated when a new scene is shown), ``controller`` (its
``SceneController``), ``volviz`` and ``np`` in scope (issue #28's missing tools).

qtconsole and ipykernel are the optional extra ``console`` (``pip install volviz[console]``); without them (and in the
packaged app, which leaves them out) the dock says so in one line. The kernel starts the first time the dock is
opened and is shut down when the window closes: its namespace (which holds the window) is emptied, and what the
shell put in ``builtins`` and ``os.environ`` is taken out again, so that no kernel outlives its window."""
from __future__ import annotations

import builtins
import os
from typing import Any, Optional

from PySide6.QtCore import QObject, Qt
from PySide6.QtWidgets import QDockWidget, QLabel, QMenu

#: what the dock says where qtconsole or ipykernel cannot be imported
MISSING = "The Python console needs qtconsole and ipykernel, which are not installed: pip install 'volviz[console]'"

#: the dock's height when it first opens (pixels): about a dozen lines
CONSOLE_HEIGHT = 240

#: names pushed to the console, described in its banner
BANNER = ("volviz console: window (the main window), session (the shown session), controller (its scene), volviz, "
          "np\n")


def console_modules() -> Optional[tuple[Any, Any]]:
    """qtconsole's in-process kernel manager and Jupyter widget classes, or None when they cannot be imported."""
    os.environ.setdefault("QT_API", "pyside6")                   # qtpy: the binding the app uses
    os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")  # ipykernel's debugger: no note about frozen modules
    try:
        from qtconsole.inprocess import QtInProcessKernelManager
        from qtconsole.rich_jupyter_widget import RichJupyterWidget
    except ImportError:
        return None
    return QtInProcessKernelManager, RichJupyterWidget


#: what the console's first opening imports (its widget, kernel and the kernel's debugger), imported in the
#: background when the window starts, not on the GUI thread at the first View > Python Console
PRELOADED = ("qtconsole.inprocess", "qtconsole.rich_jupyter_widget", "ipykernel.inprocess.ipkernel",
             "ipykernel.debugger", "IPython.core.application", "IPython.core.completerlib",
             "IPython.core.oinspect", "tornado.queues")


def preload_console() -> None:
    """Import ``PRELOADED`` and compile the console's Python lexer on a thread of its own (Python's import lock makes
    a first opening during it wait for the rest); nothing when they are not installed."""
    import importlib
    import threading

    def load() -> None:
        if console_modules() is None:
            return
        for name in PRELOADED:
            try:
                importlib.import_module(name)
            except ImportError:
                return
        importlib.import_module("pygments.lexers").Python3Lexer()   # its rules are compiled at the first lexer

    threading.Thread(target=load, name="volviz-console-imports", daemon=True).start()


class PythonConsole(QObject):
    """The View menu's "Python Console" action and, once triggered, ``dock``: the console widget (``widget``, its
    kernel ``manager``) or, without qtconsole, a label saying how to install it (``message``)."""

    def __init__(self, window: Any, menu: QMenu) -> None:
        super().__init__(window)
        self.window = window
        self.dock: Optional[QDockWidget] = None
        self.widget: Any = None
        self.manager: Any = None
        self.message: Optional[QLabel] = None
        self._builtins: dict[str, Any] = {}
        self.action = menu.addAction("Python &Console")
        self.action.triggered.connect(self.show)
        window.scene_tree.populated.connect(self.scene_shown)
        preload_console()

    def show(self) -> None:
        """Open the dock (made, and the kernel started, the first time)."""
        if self.dock is None:
            self.dock = QDockWidget("Python console", self.window)
            self.dock.setObjectName("consoleDock")
            self.dock.setWidget(self._console() or self._missing())
            self.window.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, self.dock)
            if self.window.timeline_dock.isVisible():   # a row of its own under the timeline, not beside it
                self.window.splitDockWidget(self.window.timeline_dock, self.dock, Qt.Orientation.Vertical)
        self.dock.show()
        self.dock.raise_()
        self.window.resizeDocks([self.dock], [CONSOLE_HEIGHT], Qt.Orientation.Vertical)  # a dozen lines to read

    def _missing(self) -> QLabel:
        self.message = QLabel(MISSING)
        self.message.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.window.status_label.setText(MISSING)
        return self.message

    def _console(self) -> Any:
        modules = console_modules()
        if modules is None:
            return None
        manager_class, widget_class = modules
        from traitlets.config import Config
        from ipykernel.inprocess.ipkernel import InProcessInteractiveShell

        before_builtins, before_env = dict(vars(builtins)), dict(os.environ)
        InProcessInteractiveShell.clear_instance()   # the shell is a singleton: this window's kernel gets its own
        manager = manager_class(config=Config({"HistoryManager": {"enabled": False}}))  # no history database
        manager.start_kernel()
        manager.kernel.gui = "qt"
        for name in set(os.environ) - set(before_env):   # the shell sets PAGER, FORCE_COLOR... for its own pager
            del os.environ[name]
        os.environ.update({k: v for k, v in before_env.items() if os.environ.get(k) != v})   # TERM, for one
        self._builtins = before_builtins
        client = manager.client()
        client.start_channels()
        widget = widget_class()
        widget.banner = BANNER
        widget.kernel_manager, widget.kernel_client = manager, client
        self.manager, self.widget = manager, widget
        self.scene_shown()
        return widget

    def namespace(self) -> dict[str, Any]:
        """What the console has in scope: the window, its session and scene controller, volviz and numpy."""
        import numpy as np

        import volviz

        return {"window": self.window, "session": self.window.session, "controller": self.window.controller,
                "volviz": volviz, "np": np}

    def scene_shown(self) -> None:
        """A new scene is shown: ``session`` and ``controller`` in the console name it."""
        if self.manager is not None and self.manager.kernel is not None:
            self.manager.kernel.shell.push(self.namespace())

    def shutdown(self) -> None:
        """Stop the kernel (the window closes): its namespace emptied, ``builtins`` as they were before it."""
        if self.manager is None or self.manager.kernel is None:
            return
        import atexit

        from ipykernel.inprocess.ipkernel import InProcessInteractiveShell

        self.widget.kernel_client.stop_channels()
        shell = self.manager.kernel.shell
        atexit.unregister(shell.atexit_operations)
        shell.reset(new_session=False)       # the namespace (which holds the window) emptied
        self.manager.shutdown_kernel()
        InProcessInteractiveShell.clear_instance()
        for name in set(vars(builtins)) - set(self._builtins):
            delattr(builtins, name)
        for name, value in self._builtins.items():
            if getattr(builtins, name, None) is not value:
                setattr(builtins, name, value)
        for control in (self.widget._control, self.widget._page_control):   # no events into a widget torn down
            control.removeEventFilter(self.widget)
        self.manager = None
