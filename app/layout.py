"""The window's layout: where the docks go by default, and keeping the user's own arrangement between launches.

By default the viewport gets most of the window: the transfer-function editor sits at the top of a narrow right-hand
column with the other panels (scene, render settings, clipping, statistics) tabbed below it, and the timeline is one
row along the bottom. Every dock's content sits in a scroll area, so no panel's minimum size keeps the window from
fitting a laptop screen (1366x768): a panel that is too small scrolls instead of growing the window. The tabs of
tabbed docks keep their whole titles and scroll with arrow buttons (Qt elides them: on that screen the six tabs read
"S…", "Render s…", "Cl…", "Sta…", "Sl…", "Isosu…"). A dock behind a tab comes to the front when the keyboard's focus
goes into it.

The window's geometry and dock arrangement are stored in ``QSettings`` when it closes and restored when the next one
opens (``saveGeometry`` / ``saveState``); ``reset`` (View > Reset Layout) brings back the defaults.
"""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import QByteArray, QEvent, QObject, QSettings, Qt, QTimer
from PySide6.QtWidgets import QApplication, QDockWidget, QFrame, QMainWindow, QScrollArea, QTabBar, QWidget

DEFAULT_SIZE = (1280, 860)
SIDE_WIDTH = 340          # the right-hand column of panels, in pixels, by default
TF_HEIGHT = 340           # the transfer-function editor's share of that column
GEOMETRY_KEY = "window/geometry"
STATE_KEY = "window/state"
STATE_VERSION = 2         # bump when the docks change: an older saved arrangement is then ignored


def scrolled(widget: QWidget) -> QScrollArea:
    """``widget`` in a frameless scroll area that resizes it: it fills the dock, and scrolls up and down when the dock
    is lower than the widget's minimum height (never sideways: the dock is at least as wide as the widget needs)."""
    area = QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    area.setFrameShape(QFrame.Shape.NoFrame)
    scrolls_focus = area.focusPolicy()

    def tab_stop_when_scrolling(low: int, high: int) -> None:
        """A Tab stop (keys then scroll it) only while there is something to scroll: else the area is all its
        widget, and the focus on it would show nowhere; its controls take the focus either way."""
        area.setFocusPolicy(scrolls_focus if high > low else Qt.FocusPolicy.NoFocus)

    bar = area.verticalScrollBar()
    bar.rangeChanged.connect(tab_stop_when_scrolling)
    tab_stop_when_scrolling(bar.minimum(), bar.maximum())
    area.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
    scrollbar = area.verticalScrollBar().sizeHint().width()
    area.setMinimumWidth(widget.minimumSizeHint().width() + scrollbar)
    return area


def whole_titles(tabs: QTabBar) -> None:
    """``tabs`` shows each title whole, and arrow buttons when they do not all fit."""
    tabs.setElideMode(Qt.TextElideMode.ElideNone)
    tabs.setUsesScrollButtons(True)


class WindowLayout(QObject):
    """Places the docks of ``window`` (``side``: the right-hand column, first one on top, the rest tabbed below it;
    ``bottom``: along the bottom) and persists the arrangement in ``settings``."""

    def __init__(self, window: QMainWindow, settings: QSettings, side: list[QDockWidget],
                 bottom: list[QDockWidget]) -> None:
        super().__init__(window)
        self.window, self.settings = window, settings
        self.side, self.bottom = side, bottom
        self._size_on_show = False
        window.installEventFilter(self)
        app = QApplication.instance()
        if isinstance(app, QApplication):
            app.focusChanged.connect(self._focus_changed)
        window.setDockOptions(QMainWindow.DockOption.AnimatedDocks | QMainWindow.DockOption.AllowTabbedDocks
                              | QMainWindow.DockOption.AllowNestedDocks)

    def arrange(self) -> None:
        """The default arrangement (every dock shown, the first side dock in front of its tabs)."""
        w = self.window
        right, bottom = Qt.DockWidgetArea.RightDockWidgetArea, Qt.DockWidgetArea.BottomDockWidgetArea
        for dock in self.side + self.bottom:
            w.removeDockWidget(dock)
            dock.setFloating(False)
        top, tabs = self.side[0], self.side[1:]
        w.addDockWidget(right, top)
        if tabs:
            w.addDockWidget(right, tabs[0])
            w.splitDockWidget(top, tabs[0], Qt.Orientation.Vertical)
            for dock in tabs[1:]:
                w.tabifyDockWidget(tabs[0], dock)
        for dock in self.bottom:
            w.addDockWidget(bottom, dock)
        for dock in self.side + self.bottom:
            dock.show()
        if tabs:
            tabs[0].raise_()
        if w.isVisible():
            self.size_docks()
        else:  # dock sizes only take once the window is laid out: on its first show
            self._size_on_show = True

    def size_docks(self) -> None:
        """The default split: ``SIDE_WIDTH`` for the right-hand column, ``TF_HEIGHT`` for its top dock."""
        w = self.window
        w.resizeDocks([self.side[0]], [SIDE_WIDTH], Qt.Orientation.Horizontal)
        if len(self.side) > 1:
            w.resizeDocks(self.side[:2], [TF_HEIGHT, max(w.height() - TF_HEIGHT, 100)], Qt.Orientation.Vertical)

    def eventFilter(self, watched: Any, event: Any) -> bool:
        if event.type() == QEvent.Type.Show and self._size_on_show:
            self._size_on_show = False
            self.size_docks()                 # now, in the show: the viewport's first frame is drawn at its size
            layout = self.window.layout()
            if layout is not None:
                layout.activate()
            QTimer.singleShot(0, self.size_docks)   # and once laid out (a later reset sizes the docks only so)
        elif event.type() == QEvent.Type.ChildPolished and isinstance(event.child(), QTabBar):
            whole_titles(event.child())    # the window makes a tab bar for each group of tabbed docks
        return False

    def _focus_changed(self, _old: Optional[QWidget], new: Optional[QWidget]) -> None:
        """The focus went into a dock behind another's tab (Qt keeps those in the Tab chain): that dock comes to the
        front, so that the keys go to a control the user sees (issue #28: Tab from the Scene dock walked through the
        hidden Render settings, Clipping, Slices and Isosurfaces controls)."""
        dock = new
        while dock is not None and not isinstance(dock, QDockWidget):
            dock = dock.parentWidget()
        if (dock is not None and dock.window() is self.window and self.window.tabifiedDockWidgets(dock)
                and dock.visibleRegion().isEmpty()):
            dock.raise_()

    def default_size(self) -> tuple[int, int]:
        """``DEFAULT_SIZE``, or less on a smaller screen (the window's frame included)."""
        screen = self.window.screen()
        width, height = DEFAULT_SIZE
        if screen is not None:
            available = screen.availableGeometry()
            width, height = min(width, available.width()), min(height, available.height() - 28)
        return width, height

    def restore(self) -> bool:
        """Bring back the geometry and dock arrangement saved by the last window (False: none saved, or saved by a
        version with other docks)."""
        geometry, state = self.settings.value(GEOMETRY_KEY), self.settings.value(STATE_KEY)
        restored = False
        if isinstance(geometry, (QByteArray, bytes)):
            restored = self.window.restoreGeometry(QByteArray(geometry))
        if isinstance(state, (QByteArray, bytes)):
            restored = self.window.restoreState(QByteArray(state), STATE_VERSION) and restored
        if restored:
            self._size_on_show = False  # the docks keep the sizes they were saved with
        return restored

    def save(self) -> None:
        """Keep the window's geometry and dock arrangement for the next launch."""
        self.settings.setValue(GEOMETRY_KEY, self.window.saveGeometry())
        self.settings.setValue(STATE_KEY, self.window.saveState(STATE_VERSION))
        self.settings.sync()

    def reset(self) -> None:
        """View > Reset Layout: the default size and arrangement, and forget the saved ones."""
        self.settings.remove(GEOMETRY_KEY)
        self.settings.remove(STATE_KEY)
        if self.window.isMaximized() or self.window.isFullScreen():
            self.window.showNormal()
        self.window.resize(*self.default_size())
        self.arrange()

    def viewport_fraction(self, viewport: Optional[Any] = None) -> float:
        """The share of the window's area the central widget (the viewport) gets."""
        central = viewport or self.window.centralWidget()
        if central is None:  # no viewport yet
            return 0.0
        area = max(self.window.width() * self.window.height(), 1)
        return central.width() * central.height() / area
