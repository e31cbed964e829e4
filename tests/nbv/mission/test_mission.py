"""`nbv mission` read back by independent parsers: plain json and xml.etree, with this file's own
haversine and bearing (not the writer's geodesy), against the plan's geometry times the scale."""

from __future__ import annotations

import json
import math
from xml.etree import ElementTree as ET

import pytest
import trimesh

from nbv.cli import main

EARTH_M = 6_371_008.8  # the IUGG mean radius: the sphere the writer's tangent plane lies on
LAT, LON, SIZE, SAFETY, HOLD, SPACING = 47.3977, 8.5456, 20.0, 5.0, 2.0, 2.0
CENTRE_Z = 0.3  # the box below stands 0.6 m tall: the scene centre is 0.3 m up
START = [1.8, 5.5, math.radians(30.0)]
VIEWS = [[2.0, 0.3, math.radians(20.0)], [1.5, 1.9, math.radians(5.0)], [2.5, 4.0, math.radians(60.0)],
         [2.0, 3.0, math.radians(40.0)]]
KML = "{http://www.opengis.net/kml/2.2}"


def haversine_m(lat1, lon1, lat2, lon2):
    p1, p2, dp, dl = map(math.radians, (lat1, lat2, lat2 - lat1, lon2 - lon1))
    a = math.sin(dp / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * EARTH_M * math.asin(math.sqrt(a))


def bearing_deg(lat1, lon1, lat2, lon2):
    p1, p2, dl = map(math.radians, (lat1, lat2, lon2 - lon1))
    y = math.sin(dl) * math.cos(p2)
    x = math.cos(p1) * math.sin(p2) - math.sin(p1) * math.cos(p2) * math.cos(dl)
    return math.degrees(math.atan2(y, x)) % 360


def angle_gap(a, b):
    return abs((a - b + 180) % 360 - 180)


def write_plan(folder, start=START):
    """A plan folder as `nbv plan` writes it: plan.json (viewpoints, start view) and gt.ply (normalised)."""
    folder.mkdir()
    box = trimesh.creation.box((1.0, 0.5, 2 * CENTRE_Z))
    box.apply_translation([0.0, 0.0, CENTRE_Z])
    box.export(folder / "gt.ply")
    doc = {"planner": "random", "views": len(VIEWS), "viewpoints": VIEWS}
    if start is not None:
        doc["start_viewpoint"] = start
    (folder / "plan.json").write_text(json.dumps(doc))
    return folder


def mission(tmp_path, out, *extra):
    plan = tmp_path / "plan" if (tmp_path / "plan").is_dir() else write_plan(tmp_path / "plan")
    return main(["mission", str(plan), "--lat", str(LAT), "--lon", str(LON), "--target-size-m", str(SIZE),
                 "--safety-altitude-m", str(SAFETY), "--hold-s", str(HOLD),
                 "--waypoint-spacing-m", str(SPACING), "--out", str(tmp_path / out), *extra])


def expected(view):
    """Altitude, horizontal distance to the target and compass bearing from the target, scaled."""
    radius, azimuth, elevation = view
    return (SIZE * (CENTRE_Z + radius * math.sin(elevation)), SIZE * radius * math.cos(elevation),
            (90.0 - math.degrees(azimuth)) % 360)


def test_plan_file_reads_back_as_the_plan_at_scale(tmp_path, capsys):
    assert mission(tmp_path, "m.plan") == 0
    assert "4 views" in capsys.readouterr().out
    doc = json.loads((tmp_path / "m.plan").read_text())
    assert (doc["fileType"], doc["version"], doc["mission"]["version"]) == ("Plan", 1, 2)
    items = doc["mission"]["items"]
    assert [i["doJumpId"] for i in items] == list(range(1, len(items) + 1))
    assert all(i["type"] == "SimpleItem" and len(i["params"]) == 7 and i["autoContinue"] for i in items)
    assert items[0]["command"] == 22 and items[0]["params"][6] == SAFETY and items[-1]["command"] == 20
    captures = [k for k, i in enumerate(items) if i["command"] == 2000]
    assert len(captures) == len(VIEWS)
    for view, k in zip(VIEWS, captures):
        wp = items[k - 1]
        assert wp["command"] == 16 and wp["frame"] == 3 and wp["params"][0] == HOLD
        lat, lon, alt = wp["params"][4:]
        altitude, distance, from_target = expected(view)
        assert alt == pytest.approx(altitude, abs=1e-6)
        assert haversine_m(lat, lon, LAT, LON) == pytest.approx(distance, rel=1e-4)
        assert angle_gap(bearing_deg(LAT, LON, lat, lon), from_target) < 0.01  # +x east, +y north
        assert angle_gap(wp["params"][3], bearing_deg(lat, lon, LAT, LON)) < 1.0  # faces the target
        gimbal = [i for i in items[:k] if i["command"] == 1000][-1]
        assert abs(gimbal["params"][0] + math.degrees(view[2])) < 1.0
    home = doc["mission"]["plannedHomePosition"]
    assert items[0]["params"][4:6] == home[:2]  # takes off below the start view
    assert haversine_m(*home[:2], LAT, LON) == pytest.approx(expected(START)[1], rel=1e-4)


def test_legs_follow_the_viewing_shell_above_the_safety_altitude(tmp_path):
    assert mission(tmp_path, "m.plan") == 0
    items = json.loads((tmp_path / "m.plan").read_text())["mission"]["items"]
    nav = [i for i in items[1:] if i["command"] == 16]
    assert nav and all(i["params"][6] >= SAFETY for i in nav)
    captured = {k - 1 for k, i in enumerate(items) if i["command"] == 2000}
    radii = [START[0]] + [v[0] for v in VIEWS]
    leg, spans = 0, [[] for _ in VIEWS]
    for k, item in enumerate(items[:max(captured)]):  # up to the last view: the ferry home is not a leg
        if item["command"] == 16 and k not in captured:
            spans[leg].append(item["params"][4:])
        leg += k in captured
    assert all(len(span) > 5 for span in spans)
    for i, span in enumerate(spans):  # between the leg's end radii about the scene centre, scaled
        low, high = sorted(radii[i:i + 2])
        for lat, lon, alt in span:
            radius = math.hypot(haversine_m(lat, lon, LAT, LON), alt - SIZE * CENTRE_Z) / SIZE
            assert low - 1e-3 <= radius <= high + 1e-3
    path = [i["params"][4:] for i in items[:max(captured) + 1] if i["command"] == 16]
    hops = [math.hypot(haversine_m(*a[:2], *b[:2]), a[2] - b[2]) for a, b in zip(path, path[1:])]
    assert max(hops) <= SPACING * 1.001 and len(path) > 60


def test_kml_reads_back_with_a_camera_per_view_and_the_flown_path(tmp_path):
    assert mission(tmp_path, "m.kml") == 0
    root = ET.parse(tmp_path / "m.kml").getroot()
    marks = {m.findtext(f"{KML}name"): m for m in root.iter(f"{KML}Placemark")}
    assert set(marks) == {"target", "take-off", "flown path", *(f"view {i + 1}" for i in range(len(VIEWS)))}
    for i, view in enumerate(VIEWS):
        camera = marks[f"view {i + 1}"].find(f"{KML}Camera")
        lat, lon, alt = (float(camera.findtext(KML + tag)) for tag in ("latitude", "longitude", "altitude"))
        altitude, distance, _ = expected(view)
        assert camera.findtext(f"{KML}altitudeMode") == "relativeToGround"
        assert alt == pytest.approx(altitude, abs=1e-6)
        assert haversine_m(lat, lon, LAT, LON) == pytest.approx(distance, rel=1e-4)
        assert angle_gap(float(camera.findtext(f"{KML}heading")), bearing_deg(lat, lon, LAT, LON)) < 1.0
        assert float(camera.findtext(f"{KML}tilt")) == pytest.approx(90 - math.degrees(view[2]), abs=1e-6)
    line = marks["flown path"].find(f"{KML}LineString")
    assert line.findtext(f"{KML}altitudeMode") == "relativeToGround"
    heights = [float(p.split(",")[2]) for p in line.findtext(f"{KML}coordinates").split()]
    assert heights[0] == heights[-1] == 0.0 and min(heights[1:-1]) >= SAFETY


def test_a_plan_without_a_start_view_starts_at_its_first_view(tmp_path, capsys):
    write_plan(tmp_path / "plan", start=None)
    assert mission(tmp_path, "m.plan") == 0
    assert "the first view (no start view recorded)" in capsys.readouterr().out
    items = json.loads((tmp_path / "m.plan").read_text())["mission"]["items"]
    first = next(k for k, i in enumerate(items[1:], start=1) if i["command"] == 16)
    assert items[first + 1]["command"] == 2000  # climbs straight to view 1 and captures


@pytest.mark.parametrize(("extra", "message"), [
    (["--lat", "95"], "latitude 95.0 out of range"),
    (["--lon", "-200"], "longitude -200.0 out of range"),
    (["--target-size-m", "0"], "--target-size-m must be positive"),
    (["--target-size-m", "-3"], "--target-size-m must be positive"),
    (["--out", "m.txt"], "unknown mission format '.txt'; end the file name in .plan or .kml"),
    (["--safety-altitude-m", "15"], "view 2 of"),
    (["--takeoff-lat", str(LAT), "--takeoff-lon", str(LON)], "inside its footprint"),
    (["--takeoff-lat", str(LAT)], "give --takeoff-lat and --takeoff-lon together"),
])
def test_bad_input_is_a_named_error(tmp_path, capsys, extra, message):
    options = {"--lat": str(LAT), "--lon": str(LON), "--target-size-m": str(SIZE), "--out": "m.plan"}
    options.update(zip(extra[::2], extra[1::2]))
    options["--out"] = str(tmp_path / options["--out"])
    argv = ["mission", str(write_plan(tmp_path / "plan"))] + [x for pair in options.items() for x in pair]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "m.plan").exists()


def test_missing_plan_json_and_an_existing_output_are_named(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    assert main(["mission", str(tmp_path / "empty"), "--lat", "0", "--lon", "0", "--target-size-m", "10",
                 "--out", str(tmp_path / "m.kml")]) == 2
    assert "plan.json not found: PLAN_DIR must be a folder `nbv plan --out DIR` wrote" in \
        capsys.readouterr().err
    assert mission(tmp_path, "m.kml") == 0
    assert mission(tmp_path, "m.kml") == 2
    assert "exists: use --overwrite" in capsys.readouterr().err


def test_a_start_view_over_the_roof_takes_off_beside_the_footprint(tmp_path):
    write_plan(tmp_path / "plan", start=[1.5, 0.0, math.radians(85.0)])  # 2.6 m east: over the roof
    assert mission(tmp_path, "m.plan") == 0
    doc = json.loads((tmp_path / "m.plan").read_text())
    home = doc["mission"]["plannedHomePosition"]
    assert haversine_m(*home[:2], LAT, LON) == pytest.approx(SIZE * 0.5 + 2.0, abs=0.02)  # 2 m past the side
    assert angle_gap(bearing_deg(LAT, LON, *home[:2]), 90.0) < 0.01
    first = next(i for i in doc["mission"]["items"][1:] if i["command"] == 16)
    assert first["params"][6] == pytest.approx(SIZE * 2 * CENTRE_Z + SAFETY)  # ferries over the roof
