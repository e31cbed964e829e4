"""What `paper_results/README.md` maps: every result file, the JSON holding its commit and settings, what it
holds, and the command that writes it (`nbv.experiments.paper.write_index` writes the map)."""

from __future__ import annotations

from typing import NamedTuple


class Result(NamedTuple):
    """A result `README.md` maps: its file, the JSON holding its commit and settings, what it holds, and
    the command that writes it."""

    file: str
    record: str
    what: str
    command: str


LOOKS_EVAL = "scripts/looks_eval.py (commands in the file)"
"""How the rounds of issue 26's choice were scored."""
INDEX = (
    Result("table2.md", "table2.json", "Table 2 (views kept, Hausdorff, Chamfer per N and W)", "make tables"),
    Result("fig6/", "table2.json", "Fig. 6 heat maps: the grid's corners against the full scan (first seed)",
           "make tables"),
    Result("sec7.md", "table2.json", "Sec. VII summary from our Table 2 grid, our definition", "make tables"),
    Result("fig1_fig7.md", "fig1_fig7.json", "Fig. 1 and Fig. 7: one-pass episodes of the shipped policies "
           "(ours, the paper preset's)", "make tables"),
    Result("budget/budget.md", "budget/budget.json", "coverage against view budget and metres flown, AUC",
           "make tables"),
    Result("online/online.md", "online/online.json", "the shipped policy and the paper "
           "preset's against the baselines, 13 views, five held-out buildings, one pass",
           "nbv online (command in the file)"),
    Result("online/acceptance/online.md", "online/acceptance/online.json", "issue 26's acceptance, check by "
           "check: the shipped policies and the depth option (lookahead) against random views and the tuned "
           "orbits, with blank images, on eight held-out buildings (three of the trait family)",
           "nbv online (command in the file)"),
    Result("online/stereo/online.md", "online/stereo/online.json", "issue 26's acceptance for the "
           "image-only look-ahead (lookahead-stereo), with blank images, against random views and the tuned "
           "orbits on the same eight held-out buildings", "nbv online (command in the file)"),
    Result("ablations/README.md", "ablations/ablations.json", "rendering-quality ablations, one axis at a "
           "time", "make ablations"),
    Result("planners/README.md", "planners/comparison.json", "early planner comparison on the held-out "
           "chalet", "nbv compare (command in the file)"),
    Result("selection/selection.md", "selection/selection.json", "choice of the default training settings "
           "on validation buildings", "scripts/select_defaults.py"),
    Result("selection/members/README.md", "selection/members/selection.json", "the default command's "
           "members (--seed 0, 1, 2) on a larger validation",
           "scripts/select_defaults.py score --episodes 9"),
    Result("selection/round3/README.md", "selection/round3/selection.json", "its third round: batches "
           "of 32, learning rate 2e-4", "scripts/select_defaults.py --round 3"),
    Result("selection/round4/README.md", "selection/round4/selection.json", "its fourth round: a coverage "
           "term in the reward", "scripts/select_defaults.py --round 4"),
    Result("selection/round5/README.md", "selection/round5/results.json", "its fifth round: the Bag of "
           "Views observation and the trait family (issue 26)", LOOKS_EVAL),
    Result("selection/round6/README.md", "selection/round6/results.json", "its sixth round: orbit actions, "
           "a flight term, no poses: none looks", LOOKS_EVAL),
    Result("selection/round7/README.md", "selection/round7/results.json", "its seventh round: students of "
           "a teacher that reads the true surface", LOOKS_EVAL),
    Result("selection/round8/README.md", "selection/round8/results.json", "its eighth round: a look map "
           "of the directions flown", LOOKS_EVAL),
    Result("selection/round9/README.md", "selection/round9/results.json", "its ninth round: students "
           "without frames", LOOKS_EVAL),
    Result("selection/round10/README.md", "selection/round10/results.json", "its tenth round: a student of "
           "the teacher with orbit actions", LOOKS_EVAL),
    Result("selection/round11/README.md", "selection/round11/results.json", "its eleventh round: the "
           "imitation weight, a second seed; the re-ship", LOOKS_EVAL),
    Result("selection/round12/README.md", "selection/round12/results.json", "its twelfth round: a heavier "
           "flight term, a third training courtyard", LOOKS_EVAL),
    Result("selection/round13/README.md", "selection/round13/results.json", "its thirteenth round: round "
           "12's two changes together, two seeds", LOOKS_EVAL),
    Result("selection/round14/README.md", "selection/round14/results.json", "its fourteenth round: the "
           "default command's members trained on to 9000 frames", LOOKS_EVAL),
    Result("selection/round15/README.md", "selection/round15/results.json", "its fifteenth round: the "
           "default command on twice the training buildings", LOOKS_EVAL),
    Result("selection/round16/README.md", "selection/round16/results.json", "its sixteenth round: forward "
           "actions (the azimuth always advancing), teacher and students", LOOKS_EVAL),
    Result("selection/round17/README.md", "selection/round17/results.json", "its seventeenth round: 28 "
           "buildings, two more seeds, checkpoints chosen by the exact-render checks", LOOKS_EVAL),
    Result("selection/round18/README.md", "selection/round18/results.json", "its eighteenth round: the "
           "student fitted to its teacher's labels by supervision alone (scripts/dagger.py)", LOOKS_EVAL),
    Result("selection/round19/README.md", "selection/round19/results.json", "its nineteenth round: the "
           "teacher's near-ties as labels (--teacher-tolerance): students that look, and fly further",
           LOOKS_EVAL),
    Result("selection/round20/README.md", "selection/round20/seed2/results.json", "its twentieth round: "
           "round 19's near-tie setting over two more seeds, and a middle flight weight", LOOKS_EVAL),
    Result("selection/round21/README.md", "selection/round21/seed2/results.json", "its twenty-first round: "
           "the default setting over four more seeds, the checks counted by the script", LOOKS_EVAL),
    Result("selection/round22/README.md", "selection/round22/hinge_seed1/results.json", "its twenty-second "
           "round: a hinge on the flight term, longer training, and the frontier of coverage against metres",
           LOOKS_EVAL),
    Result("selection/round23/README.md", "selection/round23/privileged_seed1/results.json", "its "
           "twenty-third round: the teacher's knowledge in the student's state, and a student that ranks the "
           "teacher's steps", LOOKS_EVAL),
    Result("selection/round24/README.md", "selection/round24/lookahead_distinct/results.json", "its "
           "twenty-fourth round: the depth option's look-ahead never repeating a view (not adopted)",
           LOOKS_EVAL),
    Result("selection/round25/README.md", "selection/round25/lookahead_stereo/results.json", "its "
           "twenty-fifth round: the look-ahead on plane-sweep stereo from the images (lookahead-stereo), its "
           "stereo setting chosen on training buildings and its flight weight on validation ones",
           LOOKS_EVAL),
    Result("selection/round26/README.md", "selection/round26/three_frames_votes/results.json", "its "
           "twenty-sixth round: lookahead-stereo with three second frames, two-pair agreement and a voting "
           "occupancy grid (not adopted)", LOOKS_EVAL),
    Result("selection/round27/README.md", "selection/round27/next_to_free/results.json", "its "
           "twenty-seventh round: lookahead-stereo counting each ray's first unknown voxel or the unknown "
           "beside free space, a battery's hinge, patience with what stereo cannot measure and a longer "
           "horizon (not adopted), and what the courtyard loses", LOOKS_EVAL),
    Result("selection/round28/README.md", "selection/round28/forward/results.json", "its twenty-eighth "
           "round: lookahead-stereo on a pilot's forward steps (adopted: five of six checks)", LOOKS_EVAL),
    Result("selection/round29/README.md", "selection/round29/spacing0.5/results.json", "its twenty-ninth "
           "round: forward steps that never crowd a camera flown (not adopted)", LOOKS_EVAL),
    Result("selection/round30/README.md", "selection/round30/sight10/results.json", "its thirtieth round: "
           "forward steps that change their sight line, alone and under a battery's hinge (not adopted)",
           LOOKS_EVAL),
    Result("selection/round31/README.md", "selection/round31/sides1/results.json", "its thirty-first round: "
           "the look-ahead values the sides of surface it never measured from (OccupancyGrid.sides)",
           LOOKS_EVAL),
    Result("selection/round32/README.md", "selection/round32/battery20/results.json", "its thirty-second "
           "round: what a 20 m battery buys lookahead-stereo at 20 views (informational)", LOOKS_EVAL),
    Result("selection/round33/README.md", "selection/round33/batteryfollows/results.json", "its "
           "thirty-third round: a battery that follows the view budget, at 16 views (adopted)", LOOKS_EVAL),
    Result("selection/round34/README.md", "selection/round34/sides3_hinge/results.json", "its "
           "thirty-fourth round: the sides term at 3 under the battery's hinge (not adopted)", LOOKS_EVAL),
    Result("selection/round35/README.md", "selection/round35/steep60/results.json", "its "
           "thirty-fifth round: a steep band of sight directions, both validation courtyards (not adopted)",
           LOOKS_EVAL),
    Result("selection/round36/README.md", "selection/round36/steep60_blind/results.json", "its "
           "thirty-sixth round: a steep band that measures no side, and a 45-degree ceiling (not adopted by "
           "its rule)", LOOKS_EVAL),
    Result("selection/round37/README.md", "selection/round37/steep60_blind/results.json", "its "
           "thirty-seventh round: round 36's blind steep band from start views never flown (adopted)",
           LOOKS_EVAL),
    Result("selection/round38/README.md", "selection/round38/pace_starts0-5/results.json", "its "
           "thirty-eighth round: a battery spent at an even pace (not adopted)", LOOKS_EVAL),
    Result("selection/round39/README.md", "selection/round39/route_starts0-5/results.json", "its "
           "thirty-ninth round: the rest of the flight planned as one route (adopted)", LOOKS_EVAL),
    Result("selection/round40/README.md", "selection/round40/restarts_starts0-5/results.json", "its "
           "fortieth round: the route's search started again from random routes (not adopted)", LOOKS_EVAL),
    Result("selection/round41/README.md", "selection/round41/grid64_starts0-5/results.json", "its "
           "forty-first round: a 64-voxel gain grid (not adopted, stopped early)", LOOKS_EVAL),
    Result("selection/round42/README.md", "selection/round42/bound/results.json", "its forty-second round, "
           "a diagnostic: lookahead-stereo's route on the true surface, at 13, 15 and 17 m of battery",
           "python scripts/route_bound.py (commands in the file)"),
    Result("selection/round43/README.md", "selection/round43/screen_frontier1/results.json",
           "its forty-third round: a gain counting surface, not unknown depth, screened on exact depth (not "
           "adopted)",
           LOOKS_EVAL),
    Result("selection/round44/README.md", "selection/round44/screen_sides2/results.json",
           "its forty-fourth round: the worth of a side never measured, 2 and 0.5, screened on exact depth "
           "(not adopted)",
           LOOKS_EVAL),
    Result("selection/round45/README.md", "selection/round45/stereo_starts0-5/results.json",
           "its forty-fifth round: sides from eight horizontal sectors, passed the screen on exact depth, "
           "lost a courtyard on stereo (not adopted, stopped early)", LOOKS_EVAL),
    Result("selection/round46/README.md", "selection/round46/reference/results.json",
           "its forty-sixth round, a diagnostic: lookahead-stereo and eight sectors on four training "
           "courtyards no round chose on", LOOKS_EVAL),
    Result("selection/round47/README.md", "selection/round47/steep70/results.json",
           "its forty-seventh round: exact depth on the fresh courtyards, the steep band at 70 and 75 "
           "degrees (missed its bar, not adopted)", LOOKS_EVAL),
    Result("selection/round48/README.md", "selection/round48/bands2/results.json",
           "its forty-eighth round: sides told by two vertical bands (missed its bar, not adopted)",
           LOOKS_EVAL),
    Result("selection/round49/README.md", "selection/round49/bands1/results.json",
           "its forty-ninth round: sides told by the horizontal sector alone (flew round 48's flights, not "
           "adopted)", LOOKS_EVAL),
    Result("selection/round50/README.md", "selection/round50/padding_free/results.json",
           "its fiftieth round: the grid's padding starts free (missed its bar, not adopted)", LOOKS_EVAL),
    Result("selection/round51/README.md", "selection/round51/stereo_mask/results.json",
           "its fifty-first round: stereo's pixels on exact depth (a diagnostic: its wrong depths cost 1.0 "
           "of its 1.2 points, its density 0.2); no depth outside the box (+0.18, not on); the grid's votes "
           "(+1.03 on the fresh courtyards, 95.45 % on the validation buildings: adopted)", LOOKS_EVAL),
    Result("sfm/presets.md", "sfm/presets.json", "`nbv sfm` on each preset's full 288-view scan: registered "
           "share, models, centre and rotation errors",
           "python scripts/sfm_presets.py (commands in the file)"),
    Result("sfm/register_curve.md", "sfm/register_curve.json", "COLMAP registration per view count and "
           "resolution: the policy, the tuned orbit, random views", "scripts/sfm_register_curve.py"),
    Result("sfm/links/register_curve.md", "sfm/links/register_curve.json", "the same for random and greedy "
           "views kept linked by --min-matches 15", "scripts/sfm_register_curve.py --min-matches 15"),
    Result("sfm/greedy/register_curve.md", "sfm/greedy/register_curve.json", "the same for greedy views "
           "without the constraint", "scripts/sfm_register_curve.py"),
    Result("sfm/tiled/register_curve.md", "sfm/tiled/register_curve.json", "COLMAP registration per view "
           "count and resolution, on the tiled look: the policy, the tuned orbit, random views",
           "scripts/sfm_register_curve.py --scene medieval_tavern@tiled"),
    Result("sfm/demo/results.md", "sfm/demo/results.json", "`nbv demo --sfm --min-matches 15`: the full, "
           "refined and linked sets' registration, the view reductions, the online half",
           "nbv demo --sfm --min-matches 15"),
    Result("match_cosine/match_cosine.md", "match_cosine/match_cosine.json", "the match cosine c re-chosen "
           "on the detailed look: views kept per Table 2 cell for c = 0.76 to 0.8",
           "python scripts/match_cosine.py (command in the file)"),
    Result("captures/captures.md", "captures/captures.json", "the full scan as COLMAP and nerfstudio "
           "captures: kept-frame Jaccard against the scan's own", "scripts/capture_agreement.py"),
)
"""Every result `README.md` may map, in its order."""

