"""The README's stills: each paper's tracker on the scene it was built for, ByteTrack on mot17_like, and the
side-by-side GIF.

Each still is what `env.render()` shows once the agent hands its tracker's drawings to the env (the hand-over any
Gym agent can use, `RecordVideo` included). Run from the repository root:

    python docs/experiments/stills.py
"""

from __future__ import annotations

from mtt_sim.lab.docsite import still
from mtt_sim.lab.experiment import run_episodes

STILLS = [  # (scenario, tracker, file, frame, seed, render scale)
    ("crossing", "jpda", "docs/still_jpda_crossing.jpg", 60, 1, 2),
    ("umbrellas", "pf", "docs/still_pf_umbrellas.jpg", 40, 0, 1),
    ("books", "ipf:samples=0", "docs/still_ipf_books.jpg", 60, 1, 1),
    ("mot17_like", "lmb", "docs/still_lmb_mot17_like.jpg", 60, 0, 1),
    ("mot17_like", "bytetrack", "docs/demo.jpg", 120, 0, 1),
]

if __name__ == "__main__":
    for args in STILLS:
        still(*args)
        print(args[2])
    run_episodes("crossing", ["sort", "jpda"], seed=1, video="docs/compare_sort_jpda_crossing.gif", steps=100)
    print("docs/compare_sort_jpda_crossing.gif")
