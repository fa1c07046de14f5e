"""Build step of the pleat Python package: bundles the shared library into the wheel.

``pip install ./bindings/python`` runs this from the repository. The library it bundles is, in
order:

1. ``$PLEAT_BUNDLE_LIBRARY``, a path to a built ``libpleat.so`` (packagers, CI, a debug build);
2. otherwise the repository's ``cargo build --release --lib`` output (cargo is run first, a
   no-op when the release library is up to date; ``$CARGO_TARGET_DIR`` is honoured).

The copy is stripped of debug information when ``strip`` is available (the release profile
keeps line tables: 60+ MB). The package version is Cargo.toml's, so ``pleat.version()``
(the library's ``pleat_version()``), ``pleat --version`` and the package metadata agree.
"""

import os
import re
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
LIB_NAME = "libpleat.dylib" if sys.platform == "darwin" else "libpleat.so"


def cargo_version():
    """The [package] version of the repository's Cargo.toml (the library's version)."""
    path = os.path.join(ROOT, "Cargo.toml")
    if not os.path.exists(path):
        sys.exit("setup.py: Cargo.toml not found next to bindings/python; build from the repository")
    in_package = False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("["):
                in_package = line.strip() == "[package]"
            m = re.match(r'\s*version\s*=\s*"([^"]+)"', line)
            if in_package and m:
                return m.group(1)
    sys.exit("setup.py: no [package] version in Cargo.toml")


def library_to_bundle():
    """Path of the shared library to copy into the package (see the module doc)."""
    given = os.environ.get("PLEAT_BUNDLE_LIBRARY")
    if given:
        if not os.path.isfile(given):
            sys.exit(f"setup.py: PLEAT_BUNDLE_LIBRARY={given} is not a file")
        return given
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
    cargo = shutil.which("cargo")
    if cargo is None:
        sys.exit("setup.py: cargo not found; install Rust or set PLEAT_BUNDLE_LIBRARY to a built libpleat.so")
    print("setup.py: cargo build --release --lib", flush=True)
    subprocess.run([cargo, "build", "--release", "--lib"], cwd=ROOT, check=True)
    return os.path.join(target, "release", LIB_NAME)


class BuildPyWithLibrary(build_py):
    """build_py that also copies the shared library into the built package."""

    def run(self):
        super().run()
        src = library_to_bundle()
        dst_dir = os.path.join(self.build_lib, "pleat")
        os.makedirs(dst_dir, exist_ok=True)
        dst = os.path.join(dst_dir, LIB_NAME)
        shutil.copyfile(src, dst)
        os.chmod(dst, 0o755)
        strip = shutil.which("strip")
        if strip and sys.platform.startswith("linux"):
            subprocess.run([strip, "--strip-debug", dst], check=True)
        print(f"setup.py: bundled {src} as {dst}", flush=True)


class BinaryDistribution(Distribution):
    """The wheel carries a native library: tag it for this platform, not 'any'."""

    def has_ext_modules(self):
        return True


CMDCLASS = {"build_py": BuildPyWithLibrary}
try:  # setuptools >= 70 has its own bdist_wheel; older ones use the wheel package's
    from setuptools.command.bdist_wheel import bdist_wheel
except ImportError:
    from wheel.bdist_wheel import bdist_wheel


class BdistWheelAnyPython(bdist_wheel):
    """Tag the wheel py3-none-<platform>: the library is loaded with ctypes, so one wheel
    serves every Python 3 on the platform."""

    def get_tag(self):
        _, _, platform = super().get_tag()
        return "py3", "none", platform


CMDCLASS["bdist_wheel"] = BdistWheelAnyPython

setup(
    version=cargo_version(),
    cmdclass=CMDCLASS,
    distclass=BinaryDistribution,
    zip_safe=False,
)
