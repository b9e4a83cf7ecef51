import pytest

from tests.wiring import wire


@pytest.fixture
def wired(library, tmp_path):
    built = wire(library, tmp_path)
    with built.session:
        yield built
