"""The render setting ``backend`` (``volviz.render.backend``): the GL driver of a real offscreen render window, the
choice per view kind, the session's validation of the setting, and ``volviz info --gl``."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from volviz import session as S
from volviz.render.backend import (GLInfo, choose_backend, gpu_in_thread, is_software_renderer, offscreen_gl_info,
                                   parse_capabilities)

HARDWARE = GLInfo("NVIDIA Corporation", "NVIDIA H100 80GB HBM3/PCIe/SSE2", "4.6.0 NVIDIA 550.54.15")
LLVMPIPE = GLInfo("Mesa/X.org", "llvmpipe (LLVM 15.0.6, 256 bits)", "4.5 (Core Profile) Mesa 22.3.6")


@pytest.mark.parametrize("renderer, software", [
    ("llvmpipe (LLVM 15.0.6, 256 bits)", True), ("softpipe", True), ("Mesa X11 swrast", True),
    ("Google SwiftShader", True), ("ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero)), SwiftShader driver)",
                                   True),
    ("NVIDIA H100 80GB HBM3/PCIe/SSE2", False), ("AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 15.0.7)", False),
    ("Mesa Intel(R) UHD Graphics 620 (KBL GT2)", False), ("", False)])
def test_software_renderers_are_recognised(renderer: str, software: bool) -> None:
    assert is_software_renderer(renderer) is software


def test_auto_picks_the_gpu_on_hardware_and_the_measured_faster_path_on_llvmpipe() -> None:
    for kind in ("pt", "regular", "nature", "iso"):
        assert choose_backend("auto", kind, HARDWARE) == "gpu"
        assert choose_backend("auto", kind, LLVMPIPE) == ("gpu" if kind == "iso" else "cpu")   # docs/bench/iso.md
        for setting in ("gpu", "cpu"):                      # an explicit setting is honoured on either driver
            assert choose_backend(setting, kind, HARDWARE) == setting
            assert choose_backend(setting, kind, LLVMPIPE) == setting
    with pytest.raises(ValueError, match="unknown backend 'fast'"):
        choose_backend("fast", "pt", HARDWARE)
    with pytest.raises(ValueError, match="unknown view kind"):
        choose_backend("auto", "terrain", HARDWARE)


def test_the_gpu_pass_draws_in_a_thread_on_a_software_rasteriser_unless_told_otherwise() -> None:
    """``gpu_thread``: "auto" (or missing) draws the GPU PT pass in a thread on llvmpipe only; "on" and "off" are
    honoured on either driver; the session refuses another value, naming the field."""
    assert gpu_in_thread({}, LLVMPIPE) and gpu_in_thread({"gpu_thread": "auto"}, LLVMPIPE)
    assert not gpu_in_thread({}, HARDWARE) and not gpu_in_thread({"gpu_thread": "auto"}, HARDWARE)
    for info in (HARDWARE, LLVMPIPE):
        assert gpu_in_thread({"gpu_thread": "on"}, info) and not gpu_in_thread({"gpu_thread": "off"}, info)
    doc = _doc("gpu")
    doc["render"]["options"]["gpu_thread"] = "sometimes"
    with pytest.raises(S.SessionError, match="render.options.gpu_thread"):
        S.session_from_dict(doc, "scene.json")


def test_capabilities_of_a_real_offscreen_window() -> None:
    info = offscreen_gl_info()
    assert info.renderer and info.vendor and info.version[0].isdigit()
    assert choose_backend("auto", "pt", info) == ("cpu" if info.software else "gpu")
    text = ("OpenGL vendor string:  Mesa/X.org\nOpenGL renderer string:  llvmpipe (LLVM 15.0.6, 256 bits)\n"
            "OpenGL version string:  4.5 (Core Profile) Mesa 22.3.6\nOpenGL extensions:  \n  GL_AMD_x\n")
    assert parse_capabilities(text) == LLVMPIPE


def _doc(backend: object) -> dict:
    doc = S.session_to_dict(S.Session())
    doc["render"]["options"]["backend"] = backend
    return doc


def test_the_session_refuses_an_unknown_backend_and_keeps_a_known_one() -> None:
    with pytest.raises(S.SessionError) as info:
        S.session_from_dict(_doc("fast"), "scene.json")
    assert "render.options.backend" in str(info.value) and "auto, gpu, cpu" in str(info.value)
    with pytest.raises(S.SessionError, match="expected a string"):
        S.session_from_dict(_doc(1), "scene.json")
    session = S.session_from_dict(_doc("gpu"), "scene.json")
    assert session.render.options["backend"] == "gpu"
    again = S.session_from_dict(json.loads(json.dumps(S.session_to_dict(session))), "scene.json")
    assert again.render.options["backend"] == "gpu"


def test_info_gl_prints_the_renderer_and_the_auto_backends() -> None:
    info = offscreen_gl_info()
    run = subprocess.run([sys.executable, "-m", "volviz.cli", "info", "--gl"], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert info.renderer in run.stdout and info.version in run.stdout
    auto = choose_backend("auto", "pt", info)
    assert f"pt: {auto}" in run.stdout
    run = subprocess.run([sys.executable, "-m", "volviz.cli", "info", "--gl", "--json"], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    doc = json.loads(run.stdout)
    assert doc["opengl_renderer"] == info.renderer and doc["auto_backend"]["pt"] == auto
    assert doc["auto_gpu_pt_in_thread"] is info.software
    run = subprocess.run([sys.executable, "-m", "volviz.cli", "info"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 2 and "info needs a file, or --gl" in run.stderr
