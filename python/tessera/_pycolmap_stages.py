"""pycolmap's pipeline calls and Database reads, on Tessera's stages and workspace.

pycolmap names a database file; Tessera's stages work in a workspace folder that holds
database.db, so database_path must be WORKSPACE/database.db. Each call runs Tessera's stage
with a bundled recipe (the `manifest` keyword picks another):
  extract_features    -> extract  (default.json: SIFT)
  match_exhaustive    -> match    (default.json: every pair)
  match_sequential    -> match    (sequential.json: neighbours in name order)
  incremental_mapping -> map      (default.json: the incremental mapper)
  global_mapping      -> map      (global.json: the global mapper)
The mapping calls return {index: Reconstruction} as pycolmap's and write each model to
output_path/<index> (COLMAP binary), as COLMAP's mapper does."""

import os
from typing import Any, Dict, List, Sequence, Union

from . import _tessera
from ._model_edits import ManifestLike, output_folder, workspace_of
from ._tessera import Database, Image, InputError, Reconstruction

PathLike = Union[str, "os.PathLike[str]"]


def _no_subset(function: str, image_names: Sequence[str]) -> None:
    if image_names:
        raise InputError(f"{function}: image_names: Tessera ingests a whole folder; put the "
                         f"images wanted in a folder of their own")


def extract_features(database_path: PathLike, image_path: PathLike,
                     image_names: Sequence[str] = (), manifest: ManifestLike = None,
                     threads: int = 0) -> None:
    """Ingests image_path's images and detects their features into database_path's
    workspace (tessera.extract; manifest None: default.json)."""
    from . import extract

    name = "extract_features"
    _no_subset(name, image_names)
    extract(images=image_path, output=workspace_of(name, database_path), manifest=manifest,
            threads=threads)


def match_exhaustive(database_path: PathLike, manifest: ManifestLike = None,
                     threads: int = 0) -> None:
    """Matches and verifies every pair of the workspace's images (tessera.match with a
    recipe whose pair selector is "exhaustive")."""
    from . import match

    match(output=workspace_of("match_exhaustive", database_path), manifest=manifest,
          threads=threads)


def match_sequential(database_path: PathLike, manifest: ManifestLike = None,
                     threads: int = 0) -> None:
    """Matches and verifies the pairs of images near in name order (tessera.match with
    sequential.json)."""
    from . import match

    match(output=workspace_of("match_sequential", database_path),
          manifest="sequential" if manifest is None else manifest, threads=threads)


def _mapping(function: str, database_path: PathLike, image_path: PathLike,
             output_path: PathLike, manifest: ManifestLike, threads: int) -> Dict[int, Reconstruction]:
    from . import map as map_stage

    workspace = workspace_of(function, database_path)
    if not os.path.isdir(image_path):
        raise InputError(f"{function}: image_path: {os.fspath(image_path)}: no such folder")
    output_folder(function, output_path)
    summary = map_stage(output=workspace, images=image_path, manifest=manifest, threads=threads)
    models: Dict[int, Reconstruction] = {}
    sparse = os.path.join(workspace, _tessera._MODELS_FOLDER)
    for index in range(int(summary["num_models"])):
        model = Reconstruction(os.path.join(sparse, str(index)))
        target = os.path.join(output_path, str(index))
        if not _same_folder(target, os.path.join(sparse, str(index))):
            os.makedirs(target, exist_ok=True)
            model.write(target)
        models[index] = model
    return models


def _same_folder(a: str, b: str) -> bool:
    return os.path.exists(a) and os.path.samefile(a, b)


def incremental_mapping(database_path: PathLike, image_path: PathLike, output_path: PathLike,
                        manifest: ManifestLike = None, threads: int = 0) -> Dict[int, Reconstruction]:
    """Maps the workspace with the incremental mapper (tessera.map with default.json);
    {index: Reconstruction}, each also written to output_path/<index>. NoModelError when no
    model was built (pycolmap returns {})."""
    return _mapping("incremental_mapping", database_path, image_path, output_path, manifest,
                    threads)


def global_mapping(database_path: PathLike, image_path: PathLike, output_path: PathLike,
                   manifest: ManifestLike = None, threads: int = 0) -> Dict[int, Reconstruction]:
    """As incremental_mapping, with the global mapper (global.json)."""
    return _mapping("global_mapping", database_path, image_path, output_path,
                    "global" if manifest is None else manifest, threads)


# ---- Database: pycolmap's read_* names beside Tessera's ----

def _open(path: PathLike) -> Database:
    """pycolmap's Database.open(path): the database, read-only (Tessera's stages write it)."""
    return Database(path)


def _read_all_images(self: Database) -> List[Image]:
    """The images, by ascending id, with name, camera_id and keypoints (no pose)."""
    return [image for _, image in sorted(self.images.items())]


class FeatureDescriptors:
    """What pycolmap 4's Database.read_descriptors returns: the (M, D) uint8 rows in .data."""

    __slots__ = ("data",)

    def __init__(self, data: Any) -> None:
        self.data = data

    def __repr__(self) -> str:
        return f"FeatureDescriptors(data=<{self.data.shape[0]} x {self.data.shape[1]} uint8>)"


def _read_descriptors(self: Database, image_id: int) -> FeatureDescriptors:
    """pycolmap 4's: the image's descriptors in .data, (M, D) uint8 (Database.descriptors
    gives the array itself)."""
    return FeatureDescriptors(self.descriptors(image_id))


def _close(self: Database) -> None:
    """Nothing to release early: the file is closed when the object is freed."""


def _enter(self: Database) -> Database:
    return self


def _exit(self: Database, *exception: object) -> None:
    return None


def attach() -> None:
    database_class: Any = Database
    database_class.open = staticmethod(_open)
    database_class.read_all_images = _read_all_images
    database_class.read_keypoints = database_class.keypoints
    database_class.read_descriptors = _read_descriptors
    database_class.read_matches = database_class.matches
    database_class.read_two_view_geometry = database_class.two_view_geometry
    database_class.close = _close
    database_class.__enter__ = _enter
    database_class.__exit__ = _exit
