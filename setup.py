"""`pip install .`: configures and builds Tessera with CMake, installs it into a staging
folder, and puts it in the wheel: the package `tessera` (the extension, its Python layer,
stubs and py.typed) where the environment keeps packages, and the plugins, the recipes
(manifests) and the `tessera` CLI as the wheel's data, below the environment's prefix
(lib/tessera/plugins, share/tessera/manifests, bin/), where the extension finds them from
its own location (python/src/module.cc).

The CMake build folder is build-pip, configured for the install with the quickstart's
compile options (Release, warnings as errors; no tests, benchmarks or GUI) and kept between
installs, so a second install rebuilds only what changed. ccache is used when it is on
PATH, as scripts/compiler_cache.sh sets it up: with the checkout as base directory, and the
folder beside build/ at the same depth, so that the compile lines are the quickstart's and
its objects are reused. TESSERA_PIP_BUILD_DIR names another: one already configured and
built (the developer's build/, as the python_pip_install test uses) is installed as it is,
without a second build of the same sources. TESSERA_PIP_JOBS: parallel jobs (default 2).
CMake's progress shows with `pip install -v`."""

import os
import pathlib
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

# pip builds the wheel with this Python's own `wheel` package (--no-build-isolation: offline);
# without it setuptools says only "invalid command 'bdist_wheel'".
try:
    import wheel  # noqa: F401
except ImportError:
    sys.exit(f"Tessera's setup.py: {sys.executable} has no `wheel` package, so pip cannot build "
             "a wheel with it (\"invalid command 'bdist_wheel'\"). Install with Debian's "
             "/usr/bin/python3 (python3-wheel, python3-dev, pybind11-dev, python3-numpy: "
             "`/usr/bin/python3 -m venv --system-site-packages venv`), or give this Python "
             "wheel, numpy and pybind11 and its development headers; see docs/python.md, "
             "'Which Python'.")

# The module's arrays are numpy's; without it CMake would build everything else first and
# then no extension.
try:
    import numpy  # noqa: F401
except ImportError:
    sys.exit(f"Tessera's setup.py: {sys.executable} has no `numpy`, which the module needs to "
             "build and run. Install with Debian's /usr/bin/python3 (python3-numpy: "
             "`/usr/bin/python3 -m venv --system-site-packages venv`), or `pip install numpy` "
             "into this environment first; see docs/python.md, 'Which Python'.")

ROOT = pathlib.Path(__file__).resolve().parent
VERSION = re.search(r"project\(Tessera VERSION ([0-9.]+)",
                    (ROOT / "CMakeLists.txt").read_text()).group(1)
# Not in the wheel: what builds against Tessera, not what runs it.
LEFT_OUT = ("include", "lib/cmake", "share/doc")


def python_subdir():
    """Where this environment keeps packages, relative to the prefix data files go to."""
    return os.path.relpath(sysconfig.get_path("platlib"), sysconfig.get_path("data"))


def build_dir():
    return pathlib.Path(os.environ.get("TESSERA_PIP_BUILD_DIR", ROOT / "build-pip"))


def configured_python_subdir(folder):
    """TESSERA_PYTHON_SUBDIR of an already configured build folder, None if there is none."""
    cache = folder / "CMakeCache.txt"
    if not cache.is_file():
        return None
    found = re.search(r"^TESSERA_PYTHON_SUBDIR:STRING=(.*)$", cache.read_text(), re.MULTILINE)
    return found.group(1) if found else None


class CMakeBuild(build_ext):
    def run(self):
        folder = build_dir()
        stage = folder / "pip-stage"
        subdir = configured_python_subdir(folder) if "TESSERA_PIP_BUILD_DIR" in os.environ else None
        if subdir is None:  # else built already, as it is configured
            subdir = self.configure(folder)
            environment = dict(os.environ, CCACHE_BASEDIR=str(ROOT), CCACHE_NOHASHDIR="1")
            subprocess.run(["cmake", "--build", str(folder), "-j",
                            os.environ.get("TESSERA_PIP_JOBS", "2")], check=True,
                           env=environment)
        shutil.rmtree(stage, ignore_errors=True)
        subprocess.run(["cmake", "--install", str(folder), "--prefix", str(stage)], check=True,
                       stdout=subprocess.DEVNULL)
        self.collect(stage, subdir)

    @staticmethod
    def configure(folder):
        """Configures `folder` for this environment; the package's folder below the prefix."""
        subdir = python_subdir()
        configure = ["cmake", "-S", str(ROOT), "-B", str(folder), "-DCMAKE_BUILD_TYPE=Release",
                     "-DTESSERA_WERROR=ON", "-DTESSERA_BUILD_TESTS=OFF", "-DTESSERA_BUILD_BENCHMARKS=OFF",
                     "-DTESSERA_BUILD_GUI=OFF", "-DTESSERA_BUILD_PYTHON=ON",
                     "-DCMAKE_INSTALL_LIBDIR=lib",
                     f"-DPython3_EXECUTABLE={sys.executable}",
                     f"-DTESSERA_PYTHON_SUBDIR={subdir}"]
        if shutil.which("ccache"):
            configure += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache",
                          "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
        subprocess.run(configure, check=True)
        return subdir

    def collect(self, stage, subdir):
        """The staged install into the wheel: the package, and the rest as data files."""
        # The package: every file of stage/<subdir>/tessera into the wheel's tessera/.
        package = stage / subdir / "tessera"
        target = pathlib.Path(self.build_lib) / "tessera"
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(package, target)
        extension = pathlib.Path(self.get_ext_fullpath("tessera._tessera"))
        built = next(package.glob("_tessera*.so"), None)
        if built is None:
            sys.exit(f"Tessera's setup.py: CMake built no extension for {sys.executable}: it "
                     "found no pybind11, Python development files or numpy for it (its "
                     "configure output says which). Use Debian's /usr/bin/python3; see "
                     "docs/python.md, 'Which Python'.")
        if extension.parent.resolve() != target.resolve():
            extension.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(built, extension)

        # Everything else below the prefix: data files, installed relative to it.
        data_files = {}
        for path in sorted(stage.rglob("*")):
            relative = path.relative_to(stage)
            if (path.is_dir() or relative.is_relative_to(pathlib.Path(subdir))
                    or any(relative.is_relative_to(pathlib.Path(part)) for part in LEFT_OUT)):
                continue
            data_files.setdefault(str(relative.parent), []).append(str(path))
        self.distribution.data_files = sorted(data_files.items())


setup(
    version=VERSION,
    # setuptools' own folders inside the build folder, not beside CMake's build/.
    options={"build": {"build_base": str(build_dir() / "setuptools")},
             "egg_info": {"egg_base": str(build_dir())}},
    # The package comes from CMake's install (CMakeBuild.collect), not from discovery.
    packages=[],
    py_modules=[],
    ext_modules=[Extension("tessera._tessera", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
