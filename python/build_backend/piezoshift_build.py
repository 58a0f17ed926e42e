"""A minimal in-tree PEP 517 build backend for `pip install .` (docs/python.md).

It configures the project with CMake for the interpreter that runs it, builds the extension
target `_piezoshift`, and packs build/pip/python/piezoshift/ into a wheel with the standard
library's zipfile. It needs nothing from PyPI (pip finds no requirements to download), only what
scripts/install-deps installs from Debian (cmake, ninja, a compiler, pybind11-dev, python3-dev).

Environment:
  PIEZOSHIFT_PIP_BUILD_DIR  the CMake build directory (default: <source>/build/pip; kept between
                            installs, so a second install only relinks what changed)
  CMAKE_BUILD_PARALLEL_LEVEL  jobs for the build (CMake's own variable; Ninja's default otherwise)
"""

import base64
import hashlib
import json
import os
import pathlib
import subprocess
import sys
import sysconfig
import zipfile

NAME = "piezoshift"
VERSION = "0.1.0"
SUMMARY = ("Piezo-actuated phase shifter: flexure design, digital twin, calibration and "
           "experiments")

_SOURCE = pathlib.Path(__file__).resolve().parents[2]


def _tag():
    """cp311-cp311-linux_x86_64 for the running interpreter."""
    interpreter = "cp%d%d" % sys.version_info[:2]
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return "%s-%s-%s" % (interpreter, interpreter, platform)


def _metadata():
    return ("Metadata-Version: 2.1\nName: %s\nVersion: %s\nSummary: %s\n"
            "Requires-Python: >=3.9\nRequires-Dist: numpy\n" % (NAME, VERSION, SUMMARY))


def _check_interpreter():
    """Fails with the reason when this interpreter cannot build or use the package.

    The extension is compiled against the running interpreter's headers with Debian's pybind11
    and imported with its numpy; pip itself would only say "No matching distribution found for
    numpy" when another Python (pyenv, a conda one) comes first on PATH, since it cannot
    download anything here."""
    missing = []
    # In a child without pip's build-isolation paths: numpy is needed where the package runs.
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONNOUSERSITE", "PYTHONHOME")}
    if subprocess.run([sys.executable, "-c", "import numpy"], env=env,
                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode != 0:
        missing.append("numpy (Debian's python3-numpy, seen through --system-site-packages)")
    include = pathlib.Path(sysconfig.get_paths()["include"]) / "Python.h"
    if not include.exists():
        missing.append("the Python headers %s (Debian's python3-dev)" % include)
    pybind11 = [pathlib.Path(p) / "pybind11" / "pybind11Config.cmake"
                for p in ("/usr/lib/cmake", "/usr/share/cmake", "/usr/local/lib/cmake")]
    if not any(p.exists() for p in pybind11):
        missing.append("pybind11 (Debian's pybind11-dev)")
    if missing:
        raise RuntimeError(
            "piezoshift: cannot build for %s: missing %s. Build with Debian's Python: "
            "`/usr/bin/python3 -m venv --system-site-packages .venv && .venv/bin/pip install .` "
            "after scripts/install-deps (docs/python.md)." % (sys.executable, "; ".join(missing)))


def _release_preset_variables():
    """The cacheVariables of CMakePresets.json's `release` preset, inherited ones included."""
    presets = {p["name"]: p for p in
               json.loads((_SOURCE / "CMakePresets.json").read_text())["configurePresets"]}
    variables = {}

    def collect(name):
        preset = presets[name]
        inherits = preset.get("inherits", [])
        for parent in [inherits] if isinstance(inherits, str) else inherits:
            collect(parent)
        variables.update(preset.get("cacheVariables", {}))

    collect("release")
    return variables


def _build_package():
    """Runs CMake; returns the directory holding the importable package."""
    _check_interpreter()
    build = pathlib.Path(os.environ.get("PIEZOSHIFT_PIP_BUILD_DIR", _SOURCE / "build" / "pip"))
    configure = ["cmake", "-S", str(_SOURCE), "-B", str(build), "-G", "Ninja"]
    # The cache variables of the `release` preset, so that ccache (cmake/Ccache.cmake) reuses the
    # objects `make` compiled; the debug info is stripped from the wheel.
    configure += ["-D%s=%s" % kv for kv in sorted(_release_preset_variables().items())]
    configure += ["-DPIEZOSHIFT_BUILD_TESTS=OFF", "-DPIEZOSHIFT_BUILD_BENCH=OFF",
                  "-DPIEZOSHIFT_BUILD_PYTHON=ON", "-DPython3_EXECUTABLE=" + sys.executable]
    subprocess.run(configure, check=True, stdout=sys.stderr)
    subprocess.run(["cmake", "--build", str(build), "--target", "_piezoshift"], check=True,
                   stdout=sys.stderr)
    package = build / "python" / NAME
    if not any(package.glob("_piezoshift*.so")):
        raise RuntimeError("piezoshift: the extension was not built (pybind11-dev and "
                           "python3-dev installed? see docs/python.md)")
    return package


def _stripped(path):
    """The file's bytes; an extension module without its debug info when `strip` exists."""
    if path.suffix != ".so":
        return path.read_bytes()
    copy = path.with_name(path.name + ".stripped")
    try:
        subprocess.run(["strip", "--strip-debug", "-o", str(copy), str(path)], check=True)
        return copy.read_bytes()
    except (OSError, subprocess.CalledProcessError):
        return path.read_bytes()
    finally:
        if copy.exists():
            copy.unlink()


def _record_line(path, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return "%s,sha256=%s,%d" % (path, digest, len(data))


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_editable(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    # Before pip resolves the numpy dependency, which it cannot download here.
    _check_interpreter()
    dist_info = pathlib.Path(metadata_directory) / ("%s-%s.dist-info" % (NAME, VERSION))
    dist_info.mkdir(parents=True, exist_ok=True)
    (dist_info / "METADATA").write_text(_metadata())
    return dist_info.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    package = _build_package()
    tag = _tag()
    wheel_name = "%s-%s-%s.whl" % (NAME, VERSION, tag)
    dist_info = "%s-%s.dist-info" % (NAME, VERSION)
    files = []
    for path in sorted(package.iterdir()):
        if path.suffix in (".py", ".so") and path.is_file():
            files.append(("%s/%s" % (NAME, path.name), _stripped(path)))
    files.append((dist_info + "/METADATA", _metadata().encode()))
    wheel = "Wheel-Version: 1.0\nGenerator: piezoshift_build\nRoot-Is-Purelib: false\nTag: %s\n"
    files.append((dist_info + "/WHEEL", (wheel % tag).encode()))
    record = [_record_line(name, data) for name, data in files]
    record.append(dist_info + "/RECORD,,")
    files.append((dist_info + "/RECORD", ("\n".join(record) + "\n").encode()))
    out = pathlib.Path(wheel_directory) / wheel_name
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as z:
        for name, data in files:
            z.writestr(name, data)
    return wheel_name
