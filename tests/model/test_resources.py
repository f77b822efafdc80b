"""Finding files: example-robot-data (a hard dependency) is found, its arms and meshes resolve.

This is the one test that says whether the installed example-robot-data is found; every
other test that uses its arms runs them (and fails if they cannot be loaded), none skips.
"""

from __future__ import annotations

from uvms_pin.model.mount.catalog import CATALOG, available_arms
from uvms_pin.model.resources import (
    example_robot_data_dir,
    package_search_path,
    resolve_resource,
)


def test_example_robot_data_is_found_with_every_catalog_arm():
    root = example_robot_data_dir()
    assert root is not None, "example-robot-data (a dependency of uvms-pin) is not found"
    assert root.name == "example-robot-data" and (root / "robots").is_dir()
    for entry in CATALOG.values():
        assert entry.urdf.is_file(), entry.name
    assert set(available_arms()) == {"reference", *CATALOG}


def test_package_urls_of_example_robot_data_resolve_without_arguments(tmp_path):
    root = example_robot_data_dir()
    assert root.parent in package_search_path()
    url = "package://example-robot-data/robots/ur_description/meshes/ur5/collision/base.stl"
    assert (
        resolve_resource(url, tmp_path)
        == root / "robots/ur_description/meshes/ur5/collision/base.stl"
    )
    # a directory the caller gives is searched first
    (tmp_path / "example-robot-data" / "robots").mkdir(parents=True)
    mine = tmp_path / "example-robot-data" / "robots" / "x.stl"
    mine.write_text("solid x\nendsolid x\n")
    url_mine = "package://example-robot-data/robots/x.stl"
    assert resolve_resource(url_mine, tmp_path, [tmp_path]) == mine
    assert resolve_resource(url_mine, tmp_path) is None
