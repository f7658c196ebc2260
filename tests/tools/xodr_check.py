"""Run in the OpenDRIVE tools environment (.venv-tools): validate an .xodr with readers we did not write.

Prints one JSON object:
  schema   — XSD 1.1 errors against the ASAM OpenDRIVE 1.8 schema shipped with asam-qc-opendrive
  checker  — the ASAM quality checker bundle: {checker id: [status, issue count]}
  roads    — pyxodr's reference line of every road, one list of [x, y] samples per geometry
  elevation — pyxodr's elevation of every road: [distance along its sampled reference line, z] pairs
"""

import json
import logging
import sys
from pathlib import Path

import numpy as np
import qc_opendrive
import xmlschema
from pyxodr.road_objects.network import RoadNetwork
from qc_baselib import Configuration, Result
from qc_opendrive import constants
from qc_opendrive.main import run_checks

logging.disable(logging.CRITICAL)


def schema_errors(path: str) -> list[str]:
    schema = xmlschema.XMLSchema11(Path(qc_opendrive.__file__).parent / "schema" / "1.8.0" / "OpenDRIVE_Core.xsd")
    return [str(error.reason or error)[:300] for error in schema.iter_errors(path)]


def checker(path: str) -> dict[str, list]:
    config = Configuration()
    config.set_config_param("InputFile", path)
    config.register_checker_bundle(constants.BUNDLE_NAME)
    result = Result()
    result.register_checker_bundle(name=constants.BUNDLE_NAME, description="OpenDrive checker bundle", version="test", summary="")
    result.set_result_version(version="test")
    run_checks(config, result)
    bundle = result.get_checker_bundle_result(constants.BUNDLE_NAME)
    return {c.checker_id: [str(c.status.value if hasattr(c.status, "value") else c.status), len(c.issues)] for c in bundle.checkers}


def roads(path: str) -> tuple[dict[str, list], dict[str, list]]:
    network = RoadNetwork(path, resolution=0.5)
    found, heights = {}, {}
    for road in network.get_roads():
        line = road.reference_line  # samples every geometry at parameters evenly spaced in [0, 1]
        found[road.id] = [np.asarray(c, dtype=float).tolist() for c in road.coordinates_sorted_by_distance]
        distance = np.append(0.0, np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1)))
        heights[road.id] = np.column_stack([distance, road.z_coordinates]).tolist()
    return found, heights


if __name__ == "__main__":
    target = sys.argv[1]
    lines, heights = roads(target)
    print(json.dumps({"schema": schema_errors(target), "checker": checker(target), "roads": lines, "elevation": heights}))
