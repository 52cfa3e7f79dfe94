"""slice() writes the bytes of `trivox slice` for the bundled scenes built from ../shared
(examples/shared_scenes/: the duck, the teapot and the trimmed boxes), two layers from the
middle of each; they skip when ../shared/data is absent. A file of its own, so that CTest runs
it beside test_slice.py (reading the duck builds and untangles its Coons volume)."""

import pytest

from conftest import EXAMPLES
from test_slice import compare_with_cli

SHARED_SCENE_NAMES = sorted(p.stem for p in (EXAMPLES / "shared_scenes").glob("*.json"))


@pytest.mark.parametrize("name", SHARED_SCENE_NAMES)
def test_slice_writes_the_bytes_of_the_cli_for_the_shared_examples(cli, shared_data, name, tmp_path):
    compare_with_cli(cli, EXAMPLES / "shared_scenes" / f"{name}.json", tmp_path, 2)
