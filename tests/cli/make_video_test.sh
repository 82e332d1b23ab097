#!/usr/bin/env bash
# scripts/make-video as scripts/demo uses it: a short `sdfstream fly` (every frame a PNG, with
# its -direct/-indirect layers) becomes an H.264 mp4 that ffprobe reads back with the frames'
# size, count and duration, plus a contact sheet of the expected size; a folder without frames
# or with a damaged frame gives one line naming it, a non-zero exit and no output (an existing
# video is left as it was). Exit 77 (skip) without ffmpeg.
#   make_video_test.sh SDFSTREAM SOURCE_DIR
set -euo pipefail

tool=$1
script=$2/scripts/make-video

for t in ffmpeg ffprobe; do
  if ! command -v "$t" >/dev/null 2>&1; then
    echo "SKIP: $t is not installed (apt-get install ffmpeg)"
    exit 77
  fi
done

tmp=$(mktemp -d "${TMPDIR:-/tmp}/make-video-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

failures=0
check() {  # check DESCRIPTION COMMAND...: runs the command, reports FAIL when it fails
  local what=$1
  shift
  if ! "$@"; then
    echo "FAIL: $what"
    failures=$((failures + 1))
  fi
}
# Only these names under DIR (one per line, sorted), so nothing is left behind.
only() { [ "$(ls -A "$1")" = "$2" ]; }
near() { awk -v a="$1" -v b="$2" -v e="$3" 'BEGIN { d = a - b; exit !(d <= e && -d <= e) }'; }
stream() { ffprobe -v error -select_streams v:0 -show_entries "stream=$2" -of csv=p=0 "$1"; }

# A 2 m x 1 m x 1 m box (12 tiles of 5 cm voxels, a fraction of a second to import), flown
# towards for 12 frames of 160 x 90 with no moving objects and no GI (this tests the video, not
# the lighting): a few seconds on lavapipe. The box streams in after the first frame and grows.
cat >box.obj <<'EOF'
v 0 0 0
v 2 0 0
v 2 1 0
v 0 1 0
v 0 0 1
v 2 0 1
v 2 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
EOF
printf -- '-4 1.5 0.5\n-1 1.5 0.5\n' >path.txt
"$tool" import box.obj -o world --voxel 0.05 --lods 2 --tile-voxels 32 >/dev/null 2>&1
frames=12
"$tool" fly world -o fly --path path.txt --speed 5 --frames "$frames" --width 160 --height 90 \
  --image-every 1 --no-pacing --objects 0 --gi off --layers >fly.log 2>&1 || { cat fly.log; echo "FAIL: fly"; exit 1; }
check "fly wrote $frames frames and their layers" \
  [ "$(find fly/frames -name 'frame-*.png' | wc -l)" -eq $((3 * frames)) ]

# 12 frames at 6 fps: 2 s of 160 x 90 H.264, and a 4 x 3 sheet of 64 x 36 tiles
# (4 px between and around them).
mkdir out
rc=0
"$script" fly/frames -o out/fly.mp4 --fps 6 --tile-width 64 >video.out 2>video.err || rc=$?
cat video.out video.err
check "make-video exits 0 (got $rc)" [ "$rc" -eq 0 ]
check "no error output" [ ! -s video.err ]
check "it says it wrote the video, with its duration" \
  grep -Eq '^make-video: wrote out/fly\.mp4 \(h264 160x90, 12 frames at 6 fps, duration 2\.0+ s' video.out
check "it says it wrote the contact sheet" \
  grep -q '^make-video: wrote out/fly-contact\.png (276x124, 4x3 tiles of frame-0000 \.\.\. frame-0011' video.out
check "the video and the sheet, nothing else" only out "$(printf 'fly-contact.png\nfly.mp4')"
check "codec h264" [ "$(stream out/fly.mp4 codec_name)" = h264 ]
check "pixel format yuv420p" [ "$(stream out/fly.mp4 pix_fmt)" = yuv420p ]
check "160 x 90 (got $(stream out/fly.mp4 width,height))" [ "$(stream out/fly.mp4 width,height)" = 160,90 ]
check "6 fps" [ "$(stream out/fly.mp4 r_frame_rate)" = 6/1 ]
packets=$(ffprobe -v error -select_streams v:0 -count_packets -show_entries stream=nb_read_packets \
  -of csv=p=0 out/fly.mp4)
check "$frames frames (got $packets)" [ "$packets" = "$frames" ]
duration=$(ffprobe -v error -show_entries format=duration -of csv=p=0 out/fly.mp4)
check "duration frames/fps = 2 s (got $duration)" near "$duration" 2 0.05
check "the video decodes without errors" \
  [ -z "$(ffmpeg -nostdin -v error -i out/fly.mp4 -f null - 2>&1)" ]
# The last frame shows the box against the sky (the sky alone spans a few grey levels).
ffmpeg -nostdin -v error -i out/fly.mp4 -vf 'signalstats,metadata=print:file=stats.txt' -f null -
range=$(awk -F= '/YMIN=/ { lo = $2 } /YMAX=/ { hi = $2 } END { print hi - lo }' stats.txt)
check "the last frame shows the box (luma range $range > 64)" [ "${range:-0}" -gt 64 ]
moov=$(grep -obUa moov out/fly.mp4 | head -n 1 | cut -d: -f1)
mdat=$(grep -obUa mdat out/fly.mp4 | head -n 1 | cut -d: -f1)
check "+faststart: moov (${moov:-none}) before mdat (${mdat:-none})" [ "${moov:-2}" -lt "${mdat:-1}" ]
check "contact sheet is a 276 x 124 PNG (got $(stream out/fly-contact.png codec_name,width,height))" \
  [ "$(stream out/fly-contact.png codec_name,width,height)" = png,276,124 ]

# Odd frame sizes are cut to even ones (yuv420p needs them), --no-contact writes the video only.
mkdir odd oddout
for i in 0 1 2; do
  ffmpeg -nostdin -v error -i "fly/frames/frame-000$i.png" -vf crop=159:89:0:0 "odd/frame-000$i.png"
done
rc=0
"$script" odd -o oddout/odd.mp4 --fps 30 --no-contact >odd.out 2>&1 || rc=$?
cat odd.out
check "odd frames: exits 0 (got $rc)" [ "$rc" -eq 0 ]
check "odd frames: 158 x 88 (got $(stream oddout/odd.mp4 width,height 2>/dev/null))" \
  [ "$(stream oddout/odd.mp4 width,height 2>/dev/null)" = 158,88 ]
check "--no-contact: the video only" only oddout odd.mp4

# A folder without frames (only layers and other files): one line, non-zero, no output; an
# existing video and sheet stay as they were.
mkdir noframes
cp fly/frames/frame-0000-direct.png fly/frames/frame-0000-indirect.png noframes/
echo notes >noframes/frame-notes.png.txt
cp out/fly.mp4 fly.mp4.before
cp out/fly-contact.png contact.before
rc=0
"$script" noframes -o out/fly.mp4 >none.out 2>none.err || rc=$?
cat none.out none.err
check "no frames: exits non-zero" [ "$rc" -ne 0 ]
check "no frames: one line on stderr" [ "$(wc -l <none.err)" -eq 1 ]
check "no frames: nothing on stdout" [ ! -s none.out ]
check "no frames: the line names the folder and the problem" \
  grep -q '^make-video: error: noframes: no frames found' none.err
check "no frames: the existing video is untouched" cmp -s fly.mp4.before out/fly.mp4
check "no frames: the existing sheet is untouched" cmp -s contact.before out/fly-contact.png
check "no frames: nothing new beside them" only out "$(printf 'fly-contact.png\nfly.mp4')"

# A damaged (truncated) frame: named in one line, no output.
mkdir damaged empty
cp fly/frames/frame-000[0-5].png damaged/
head -c 100 fly/frames/frame-0003.png >damaged/frame-0003.png
rc=0
"$script" damaged -o empty/fly.mp4 >damaged.out 2>damaged.err || rc=$?
cat damaged.out damaged.err
check "damaged frame: exits non-zero" [ "$rc" -ne 0 ]
check "damaged frame: one line on stderr" [ "$(wc -l <damaged.err)" -eq 1 ]
check "damaged frame: the line names the frame" \
  grep -q '^make-video: error: damaged/frame-0003\.png: ' damaged.err
check "damaged frame: no output" only empty ''

# No ffmpeg on PATH: one line saying so.
rc=0
PATH=/nonexistent "$BASH" "$script" fly/frames -o empty/fly.mp4 >noff.out 2>noff.err || rc=$?
cat noff.err
check "no ffmpeg: exits non-zero" [ "$rc" -ne 0 ]
check "no ffmpeg: one line naming it" \
  [ "$(cat noff.err)" = "make-video: error: ffmpeg is not installed (apt-get install ffmpeg)" ]
check "no ffmpeg: no output" only empty ''

if [ "$failures" -ne 0 ]; then
  echo "$failures check(s) failed"
  exit 1
fi
echo "ok: $frames fly frames became a ${duration} s H.264 video and a contact sheet; bad input is one line"
