"""PEP 517 build backend: setuptools, without anything to download.

pip builds in an isolated environment and installs the backend's requirements into it
from the package index; offline that fails. This backend requires nothing: it runs
setuptools' own backend (setuptools.build_meta) with the setuptools and wheel that are
already installed (Debian: python3-setuptools, python3-wheel), found on the interpreter's
system site-packages when the isolated environment hides them. So

    python3 -m venv --system-site-packages v && v/bin/pip install ./python

works with no network and no --no-build-isolation.
"""
import site
import sys
import warnings


def _setuptools():
    try:
        import setuptools.build_meta as backend  # noqa: F401
        import wheel  # noqa: F401 - setuptools' bdist_wheel needs it
    except ImportError:
        # pip's isolated build environment removes the system site-packages from sys.path.
        for path in site.getsitepackages([sys.base_prefix]):
            if path not in sys.path:
                sys.path.append(path)
        try:
            import setuptools.build_meta as backend  # noqa: F811
            import wheel  # noqa: F401
        except ImportError as e:
            raise RuntimeError("building fsi needs setuptools (Debian: apt-get install python3-setuptools "
                               "python3-wheel)") from e
    return backend


with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    _backend = _setuptools()


def _no_requirements(config_settings=None):
    # setuptools would ask pip for 'wheel', which pip would try to download.
    return []


get_requires_for_build_wheel = _no_requirements
get_requires_for_build_sdist = _no_requirements
get_requires_for_build_editable = _no_requirements


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    return _backend.prepare_metadata_for_build_wheel(metadata_directory, config_settings)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    return _backend.build_wheel(wheel_directory, config_settings, metadata_directory)


def build_sdist(sdist_directory, config_settings=None):
    return _backend.build_sdist(sdist_directory, config_settings)


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    return _backend.prepare_metadata_for_build_editable(metadata_directory, config_settings)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    return _backend.build_editable(wheel_directory, config_settings, metadata_directory)
