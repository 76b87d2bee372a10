#!/bin/sh
# The shipped `learned` policy against SORT's rules, and over ByteTrack's candidates against ByteTrack's rules, on
# episodes it never saw: mot17_like (a still camera) and mot17_moving (a walking one), seeds 0-9, with each detector
# preset it was trained with, the MOT15 sequences' twins (mot15_frcnn preset, 2 seeds) and the real MOT15 sequences
# (a table per sequence: ETH-Bahnhof and ETH-Sunnyday are filmed walking, KITTI-13 from a car, the rest still).
#     sh docs/experiments/judge_policy.sh ../shared/data/mot15
set -e
DATA=$1
SEQS=$(ls -d "$DATA"/*/ | sed 's:/$::' | paste -sd, -)
for preset in frcnn dpm sdp; do
    echo "## mot17_like and mot17_moving, $preset preset, seeds 0-9"
    mtt-sim bench --scenarios mot17_like,mot17_moving --trackers 'sort;learned;bytetrack;learned:base=bytetrack' \
        --seeds 10 --config sensor.preset=$preset --metric MOTA,HOTA,IDF1
done
echo "## MOT15 twins (mot15_frcnn preset), seeds 0-1"
mtt-sim bench --scenarios "$SEQS" --trackers 'sort;learned;bytetrack;learned:base=bytetrack' --seeds 2 --detector synthetic \
    --config sensor.preset=mot15_frcnn --metric MOTA,HOTA,IDF1
echo "## MOT15, real detections"
mtt-sim bench --scenarios "$SEQS" --trackers 'sort;learned;bytetrack;learned:base=bytetrack' --seeds 1 --metric MOTA,HOTA,IDF1
