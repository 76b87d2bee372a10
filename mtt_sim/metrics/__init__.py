"""Multi-object tracking metrics, as TrackEval (the MOTChallenge reference) computes them.

`EpisodeMetrics.update` takes one frame of ground truth and tracks and hands it to each metric family (the
similarities and the CLEAR matching at once; the frame logged for the global passes); `summary` finishes the global
parts (the IDF1 assignment, HOTA's second pass, GOSPA). `evaluate` runs both on a whole sequence. Each family is a
class that declares its fields (`family.Field`): the summary, `METRICS`, `PER_TARGET`, the keys the command line
prints (`PRINTED`) and which way each metric is better (`goals`) come from the declarations.
Modules: family (what a family is), episode (EpisodeMetrics, evaluate), frame_log (what is kept of every frame),
clear (CLEAR and the centre errors), identity, hota, gospa, occlusion (the occlusion windows), goals.

Semantics, following TrackEval where other tools differ:

- CLEAR (MOTA, MOTP, IDSW, Frag, MT/PT/ML). Per frame, pairs with similarity >= threshold (0.5) are
  matched by a Hungarian assignment maximising similarity plus a bonus of 1000 for keeping each GT
  id's match of the *previous timestep*. An IDSW is counted when a GT id is matched to a tracker id
  other than its *last-ever* match (py-motmetrics differs in what it carries over).
  A frame with no GT or no tracks is skipped before the carry-over is reset, as in TrackEval: a
  match survives such a frame for both the bonus and Frag (py-motmetrics differs).
  Frag counts, per GT id, the times it goes from not tracked to tracked, minus one.
  MT: tracked in > 80 % of its frames; PT: >= 20 % and not MT; ML: the rest (py-motmetrics: >= 80 %).
  MOTA = (TP - FP - IDSW) / max(1, TP + FN); MOTP = mean similarity of the matches.
- Identity (IDF1, IDP, IDR): the global one-to-one assignment of GT ids to tracker ids that
  maximises the number of frames in which the pair has similarity >= threshold. TrackEval solves
  it on an augmented (G + T) square cost matrix; maximising the matched count on the G x T matrix of
  ids that have any potential match is the same optimum.
- HOTA over alpha = 0.05, 0.10, ..., 0.95: DetA, AssA (and DetRe, DetPr, AssRe, AssPr) per alpha,
  LocA = mean similarity of matches per alpha; HOTA = sqrt(DetA * AssA); reported values are the
  means over the 19 alphas.
- GOSPA (alpha = 2) on box centres with cut-off `c` and order `p`, computed with an exact
  assignment: (sum over assigned pairs of min(d, c)^p + c^p / 2 * (missed + false))^(1/p); the mean
  over frames is reported.
- CentreError and CentreErrorVar: mean and variance of the distance between the box centres of the CLEAR
  matches, pooled over targets (the error measure of the JPDA paper's Tables 3 and 4), in pixels.
- Similarity "iou" is the box IoU; "centroid" is TrackEval's point similarity
  max(0, 1 - d / zero_distance) on box centres.
- Occlusion windows (HiddenCentreError, Reacquired, Occlusions; scenes whose truth is passed to `update` as
  `everyone`): see `mtt_sim.metrics.occlusion`.
"""

from mtt_sim.metrics.clear import FrameStats
from mtt_sim.metrics.episode import METRICS, PER_TARGET, PRINTED, SUMMARY_FIELDS, EpisodeMetrics, evaluate
from mtt_sim.metrics.gospa import gospa, gospa_of_points

__all__ = ["EpisodeMetrics", "FrameStats", "evaluate", "METRICS", "PER_TARGET", "PRINTED", "SUMMARY_FIELDS", "gospa",
           "gospa_of_points"]
