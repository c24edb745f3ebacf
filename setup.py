"""Package layout: `volviz` (core), `app/` installed as `volviz_app`, `resources/` as `volviz_resources`."""
from setuptools import find_packages, setup

core = find_packages(include=["volviz", "volviz.*"])
app = ["volviz_app" + name[len("app"):] for name in find_packages(include=["app", "app.*"])]

# the data folders are listed as packages of their own (namespace packages: no __init__.py), so that setuptools
# ships their files without warning that importable folders were left out of ``packages``
data = ["volviz_resources.presets", "volviz_resources.sessions", "volviz_resources.shaders", "volviz_resources.icons"]

setup(
    packages=core + app + ["volviz_resources"] + data,
    package_dir={"volviz_app": "app", "volviz_resources": "resources"},
    package_data={"volviz_resources.presets": ["*.json"], "volviz_resources.sessions": ["*.json"],
                  "volviz_resources.shaders": ["*.glsl"], "volviz_resources.icons": ["*.svg"]},
)
