"""The HTML page: one self-contained file with plotly.js, the viewer's script and the scene, nothing fetched.

The page embeds the minified plotly.js that the ``plotly`` package ships
for offline use (:func:`plotly.offline.get_plotlyjs`, about 4.8 MB), the
viewer's script (``viewer.js`` beside this module) and the scene as a JSON
document, so that it opens by double-click, offline, and can be mailed.
"""

from __future__ import annotations

import html
import json
from importlib import resources

from plotly.offline import get_plotlyjs

__all__ = ["document"]

_TEMPLATE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; margin: 0.6em 1em; color: #222; }}
h1 {{ font-size: 1.1em; margin: 0.2em 0 0.4em; }}
#tumble-main {{ display: flex; gap: 0.8em; }}
#tumble-3d {{ flex: 3; height: 560px; min-width: 0; }}
#tumble-side {{ flex: 2; display: flex; flex-direction: column; min-width: 0; }}
#tumble-panel {{ height: 260px; }}
#tumble-polhode {{ height: 300px; }}
#tumble-controls {{ display: flex; align-items: center; gap: 0.8em; margin: 0.4em 0; }}
#tumble-slider {{ flex: 1; }}
#tumble-clock {{ font-family: ui-monospace, monospace; white-space: pre; }}
#tumble-notes {{ font-size: 0.85em; color: #555; margin: 0.3em 0; }}
</style>
</head>
<body>
<h1 id="tumble-title"></h1>
<div id="tumble-controls">
<button id="tumble-play" type="button">Play</button>
<label>speed <select id="tumble-speed"></select></label>
<input id="tumble-slider" type="range" min="0" max="0" step="1" value="0">
<span id="tumble-clock"></span>
</div>
<div id="tumble-main"><div id="tumble-3d"></div>
<div id="tumble-side"><div id="tumble-panel"></div><div id="tumble-polhode"></div></div></div>
<ul id="tumble-notes"></ul>
<script type="application/json" id="tumble-scene">{scene}</script>
<script>{plotly}</script>
<script>{viewer}</script>
</body>
</html>
"""


def _json_for_script(doc: dict) -> str:
    """JSON that cannot end its ``<script>`` element (``</`` is written ``<\\/``)."""
    return json.dumps(doc, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")


def document(scene_json: dict) -> str:
    """The page of a scene (:func:`tumble.viz.viewer._scene.as_json`)."""
    viewer = resources.files("tumble.viz.viewer").joinpath("viewer.js").read_text(encoding="utf-8")
    return _TEMPLATE.format(title=html.escape(scene_json["title"]), scene=_json_for_script(scene_json),
                            plotly=get_plotlyjs(), viewer=viewer)
