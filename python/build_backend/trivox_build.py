"""The build backend of `pip install .` (PEP 517; pyproject.toml names it): builds the Python
module with the project's own CMake build and packs it into a wheel.

It needs nothing beyond the standard library, CMake and the C++ build's packages (Debian's,
scripts/install-deps.sh), so pip installs trivox offline: pyproject.toml asks for no build
requirements, and pip's isolated build environment stays empty.

The wheel is built for the interpreter that runs pip (Python3_EXECUTABLE is set to it), in
build/pip-<python tag> below the source folder, which later installs reuse. CMake cache
settings can be passed as ``pip install . --config-settings=cmake.define.TRIVOX_NATIVE=ON``
(any ``cmake.define.NAME=VALUE``); ``--config-settings=build-dir=DIR`` moves the build.
"""

import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile

NAME = "trivox"
SUMMARY = "Slices functionally graded material objects (trivariate B-spline and NURBS volumes) for printers"


def _source_dir():
    # pip runs the backend in the source tree.
    return os.path.abspath(os.getcwd())


def _version(source):
    with open(os.path.join(source, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(trivox VERSION ([0-9.]+)", f.read())
    if not match:
        raise RuntimeError("CMakeLists.txt: no 'project(trivox VERSION x.y.z)' line")
    return match.group(1)


def _tags():
    python = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return python, python, platform


def _metadata(version):
    return (
        "Metadata-Version: 2.1\n"
        f"Name: {NAME}\n"
        f"Version: {version}\n"
        f"Summary: {SUMMARY}\n"
        "Requires-Python: >=3.9\n"
        "Requires-Dist: numpy\n"
        "License: see the repository\n"
    )


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    version = _version(_source_dir())
    info = os.path.join(metadata_directory, f"{NAME}-{version}.dist-info")
    os.makedirs(info, exist_ok=True)
    with open(os.path.join(info, "METADATA"), "w", encoding="utf-8") as f:
        f.write(_metadata(version))
    return os.path.basename(info)


def _cmake_build(source, config_settings):
    settings = dict(config_settings or {})
    tag = _tags()[0]
    build = os.path.abspath(settings.get("build-dir", os.path.join(source, "build", f"pip-{tag}")))
    defines = {
        "CMAKE_BUILD_TYPE": "Release",
        "TRIVOX_PYTHON": "ON",
        "TRIVOX_BUILD_TESTS": "OFF",
        "TRIVOX_BUILD_BENCH": "OFF",
        "Python3_EXECUTABLE": sys.executable,
    }
    for key, value in settings.items():
        if key.startswith("cmake.define."):
            defines[key[len("cmake.define."):]] = value
    configure = ["cmake", "-S", source, "-B", build] + [f"-D{k}={v}" for k, v in defines.items()]
    if shutil.which("ninja") and not os.path.exists(os.path.join(build, "CMakeCache.txt")):
        configure += ["-G", "Ninja"]
    jobs = os.environ.get("TRIVOX_JOBS", str(os.cpu_count() or 1))
    print(f"trivox: building the Python module in {build}", file=sys.stderr)
    subprocess.run(configure, check=True, stdout=sys.stderr)
    subprocess.run(["cmake", "--build", build, "--target", "trivox_python", "--parallel", jobs], check=True,
                   stdout=sys.stderr)
    return os.path.join(build, "python", NAME)


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    source = _source_dir()
    version = _version(source)
    package = _cmake_build(source, config_settings)
    python, abi, platform = _tags()
    wheel_name = f"{NAME}-{version}-{python}-{abi}-{platform}.whl"
    info = f"{NAME}-{version}.dist-info"
    files = []
    for entry in sorted(os.listdir(package)):
        if entry.endswith((".py", ".pyi", ".so")) or entry == "py.typed":
            with open(os.path.join(package, entry), "rb") as f:
                files.append((f"{NAME}/{entry}", f.read()))
    if not any(name.endswith(".so") for name, _ in files):
        raise RuntimeError(f"{package}: the build made no extension module")
    files.append((f"{info}/METADATA", _metadata(version).encode()))
    wheel = f"Wheel-Version: 1.0\nGenerator: trivox_build\nRoot-Is-Purelib: false\nTag: {python}-{abi}-{platform}\n"
    files.append((f"{info}/WHEEL", wheel.encode()))
    record = [_record_line(name, data) for name, data in files] + [f"{info}/RECORD,,"]
    files.append((f"{info}/RECORD", ("\n".join(record) + "\n").encode()))
    os.makedirs(wheel_directory, exist_ok=True)
    path = os.path.join(wheel_directory, wheel_name)
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        for name, data in files:
            z.writestr(name, data)
    return wheel_name


def build_sdist(sdist_directory, config_settings=None):
    """The files git tracks, as NAME-VERSION.tar.gz (needs git and a clone)."""
    source = _source_dir()
    version = _version(source)
    base = f"{NAME}-{version}"
    os.makedirs(sdist_directory, exist_ok=True)
    path = os.path.join(sdist_directory, f"{base}.tar.gz")
    subprocess.run(["git", "-C", source, "archive", "--format=tar.gz", f"--prefix={base}/", "-o", path, "HEAD"],
                   check=True)
    return os.path.basename(path)
