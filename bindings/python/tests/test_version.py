"""The package metadata, ``pleat.__version__`` and the library's ``pleat_version()`` agree."""
import importlib.metadata

import pytest

import pleat


def test_dunder_version_is_the_library_version():
    assert pleat.__version__ == pleat.version()
    assert len(pleat.__version__.split(".")) == 3


def test_installed_metadata_matches_the_library():
    try:
        meta = importlib.metadata.version("pleat")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("pleat is imported from the source tree, not installed")
    assert meta == pleat.version()
