"""Finding files: example-robot-data (a hard dependency) is found, its arms and meshes resolve.

This is the one test that says whether the installed example-robot-data is found; every
other test that uses its arms runs them (and fails if they cannot be loaded), none skips.
"""

from __future__ import annotations

import pytest

import uvms_pin as up
from uvms_pin.errors import NotShippedError
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


def test_a_sourced_ros_workspace_resolves_its_packages(tmp_path, monkeypatch):
    """``package://NAME/...`` in a sourced ROS workspace: ROS 1's ROS_PACKAGE_PATH (a folder
    holding packages, or the package itself) and ROS 2's AMENT_PREFIX_PATH (prefix/share/
    NAME); the caller's package_dirs first, example-robot-data last."""
    import os

    ros1 = tmp_path / "catkin_ws" / "src"
    (ros1 / "bluerov2_description" / "meshes").mkdir(parents=True)
    (ros1 / "bluerov2_description" / "meshes" / "hull.stl").write_text("solid\nendsolid\n")
    ros2 = tmp_path / "install" / "alpha_description"
    (ros2 / "share" / "alpha_description" / "meshes").mkdir(parents=True)
    (ros2 / "share" / "alpha_description" / "meshes" / "link.stl").write_text("solid\nendsolid\n")
    hull = "package://bluerov2_description/meshes/hull.stl"
    link = "package://alpha_description/meshes/link.stl"
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    assert resolve_resource(hull, tmp_path) is None and resolve_resource(link, tmp_path) is None
    package_dir = ros1 / "bluerov2_description"
    monkeypatch.setenv(
        "ROS_PACKAGE_PATH", os.pathsep.join([str(tmp_path / "none"), str(package_dir)])
    )
    assert resolve_resource(hull, tmp_path) == package_dir / "meshes" / "hull.stl"
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ros1))
    monkeypatch.setenv("AMENT_PREFIX_PATH", os.pathsep.join([str(tmp_path / "x"), str(ros2)]))
    assert resolve_resource(hull, tmp_path) == package_dir / "meshes" / "hull.stl"
    assert (
        resolve_resource(link, tmp_path)
        == ros2 / "share" / "alpha_description" / "meshes" / "link.stl"
    )
    search = package_search_path([tmp_path / "mine"])
    assert search[:3] == [tmp_path / "mine", ros1, tmp_path / "x" / "share"]
    assert search[-1] == example_robot_data_dir().parent


def test_a_file_not_shipped_is_the_projects_error_and_a_file_not_found():
    """`shipped_path` of a name it does not ship raises `NotShippedError`, which a caller
    catching uvms-pin's errors or FileNotFoundError (what it raised before) both catch."""
    assert up.shipped_path("models/uvms_lbv150.urdf").is_file()
    for caught in (NotShippedError, up.UvmsPinError, FileNotFoundError):
        with pytest.raises(caught, match=r"models/nope\.urdf is not shipped"):
            up.shipped_path("models/nope.urdf")
