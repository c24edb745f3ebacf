"""Install a small distribution the way pip does, for tests of entry-point plugins: its modules and a dist-info
folder with METADATA and entry_points.txt in a folder that the test puts on sys.path (no mocking of importlib)."""
from __future__ import annotations

import textwrap
from pathlib import Path


def install_dist(site: Path, name: str, entry_points: dict[str, dict[str, str]], modules: dict[str, str]) -> Path:
    """Write ``modules`` (module name -> source) and ``<name>-1.0.dist-info`` registering ``entry_points``
    (group -> {entry name: "module:attribute"}) into ``site``; returns ``site``."""
    dist = site / f"{name.replace('-', '_')}-1.0.dist-info"
    dist.mkdir(parents=True, exist_ok=True)
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("".join(
        f"[{group}]\n" + "".join(f"{key} = {target}\n" for key, target in items.items())
        for group, items in entry_points.items()))
    for module, source in modules.items():
        (site / f"{module}.py").write_text(textwrap.dedent(source))
    return site
