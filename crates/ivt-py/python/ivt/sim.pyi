"""The simulator (``ivt-sim``): run a scene, get numpy arrays and the summary."""

import os
from typing import Any, Dict, List, Literal, Optional, Union

SceneLike = Union[Dict[str, Any], str, "os.PathLike[str]"]
SUPPORTED_PPR: List[int]

def run(
    scene: SceneLike,
    out: Optional[Union[str, "os.PathLike[str]"]] = None,
    route: Optional[Literal["ihb_steady_state", "time_integration"]] = None,
) -> Dict[str, Any]: ...
def check_scene(scene: SceneLike) -> Dict[str, Any]: ...
def scene_dict(scene: SceneLike) -> Dict[str, Any]: ...
