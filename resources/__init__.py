"""Data files shipped with volviz: transfer-function presets, demo sessions, GLSL sources."""
from pathlib import Path

ROOT = Path(__file__).resolve().parent


def path(*parts: str) -> Path:
    """Absolute path of a shipped resource, e.g. ``path("presets", "cool-warm.json")``."""
    return ROOT.joinpath(*parts)
