"""A new user's window on a laptop (issue #28, "try it as a new user would ... a small screen"): on a 1366x768 screen
the window opens at 1280x740 (``WindowLayout.default_size``), and the right-hand column tabs six docks below the
transfer function. Found by looking at the window so: Qt elided their titles to "S…", "Render s…", "Cl…", "Sta…",
"Sl…" and "Isosu…", which name nothing. Now each tab shows its whole title, the tab bar scrolls with its arrow
buttons, and a click on each tab (after the arrows where needed) brings its dock to the front."""
from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QStyle, QTabBar, QToolButton

LAPTOP = (1280, 740)   # the window's default size on a 1366x768 screen (its frame and a panel taken off)


def _side_tabs(window) -> QTabBar:
    bars = [bar for bar in window.findChildren(QTabBar) if bar.isVisible()
            and any(bar.tabText(i) == window.scene_dock.windowTitle() for i in range(bar.count()))]
    assert len(bars) == 1, [[bar.tabText(i) for i in range(bar.count())] for bar in bars]
    return bars[0]


def test_every_dock_tab_reads_its_whole_title_and_is_reached_by_clicks(qtbot, make_window) -> None:
    window = make_window()
    window.resize(*LAPTOP)
    qtbot.waitUntil(lambda: window.size().toTuple() == LAPTOP)
    window.layout_keeper.reset()
    window.resize(*LAPTOP)
    qtbot.wait(100)            # the docks are laid out in the event loop
    bar = _side_tabs(window)
    titles = [bar.tabText(i) for i in range(bar.count())]
    assert {window.settings_dock.windowTitle(), window.iso_dock.windowTitle()} <= set(titles), titles
    metrics, space = bar.fontMetrics(), bar.style().pixelMetric(QStyle.PixelMetric.PM_TabBarTabHSpace, None, bar)
    for i, title in enumerate(titles):   # room for the whole title and the style's space around it
        need = metrics.horizontalAdvance(title) + space
        assert bar.tabRect(i).width() >= need, (title, bar.tabRect(i).width(), need)
    docks = {dock.windowTitle(): dock for dock in window.docks}
    right = [b for b in bar.findChildren(QToolButton) if b.arrowType() == Qt.ArrowType.RightArrow]
    for i, title in enumerate(titles):
        for _ in range(len(titles)):       # the arrow scrolls a hidden tab into the bar
            if bar.rect().contains(bar.tabRect(i)):
                break
            assert right and right[0].isVisible() and right[0].isEnabled(), title
            qtbot.mouseClick(right[0], Qt.MouseButton.LeftButton)
        assert bar.rect().contains(bar.tabRect(i)), title
        qtbot.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(i).center())
        qtbot.waitUntil(lambda: docks[title].widget().isVisible())
        assert bar.currentIndex() == i
