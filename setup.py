"""Package layout: `volviz` (core), `app/` installed as `volviz_app`, `resources/` as `volviz_resources`."""
from setuptools import find_packages, setup

core = find_packages(include=["volviz", "volviz.*"])
app = ["volviz_app" + name[len("app"):] for name in find_packages(include=["app", "app.*"])]

setup(
    packages=core + app + ["volviz_resources"],
    package_dir={"volviz_app": "app", "volviz_resources": "resources"},
    package_data={"volviz_resources": ["*.json", "presets/*.json", "sessions/*.json", "glsl/*.glsl"]},
)
