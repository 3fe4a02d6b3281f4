#!/usr/bin/env bash
# Outputs under attack (issue 32): a failed sequence keeps its finished frames and removes nothing it did
# not make (a frame name that is a link, to a file or to nowhere); frame patterns of any width; the
# preview movie of an odd frame size, of a failing ffmpeg, and of paths ffmpeg would misread.
# Usage: attack_outputs_test.sh HAIRGEN SOURCE_DIR CASE
source "$(dirname "$0")/cli_lib.sh" "$@"

gust="$src/configs/anjyo/gust/setup.txt"
small=(--quiet --set Hairstyle.HairDensity=5 --set "Render.Resolution=40 40")
# No temporary of hairgen's anywhere under the folder.
no_temporaries() {
  local left
  left=$(find "$1" -name '*.tmp-*')
  [ -z "$left" ] || fail "temporaries left: $left"
}
# A user's file outside the output folder, and the links to it and to nowhere that take frame names.
plant_links() { # folder frame-name-to-the-file frame-name-to-nowhere
  mkdir -p "$tmp/keep" "$1"
  echo "the user's notes" > "$tmp/keep/notes.txt"
  ln -s "$tmp/keep/notes.txt" "$1/$2"
  ln -s "$tmp/nowhere/deeper/x" "$1/$3"
}
user_file_intact() {
  [ "$(cat "$tmp/keep/notes.txt" 2>/dev/null)" = "the user's notes" ] ||
    fail "the user's file behind a frame link was replaced or removed"
  [ ! -e "$tmp/nowhere" ] || fail "a folder was made where a dangling frame link points"
}
# The number of frames an encoded movie holds, and its size.
frames_of() {
  ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "file:$1"
}
size_of() { ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=p=0 "file:$1"; }

case "$case" in
failed_sequence_links)
  # interpolate --frames 1-3 fails at frame 3 (its guides are missing), after frames 1 and 2, whose names
  # are a link to the user's file and a link into a folder that does not exist.
  expect_rc 0 "$hairgen" grow "$gust" -o "$tmp/g.hair" "${small[@]}"
  mkdir "$tmp/sim"
  cp "$tmp/g.hair" "$tmp/sim/g.0001.hair"
  cp "$tmp/g.hair" "$tmp/sim/g.0002.hair"
  plant_links "$tmp/o" c.0002.hair c.0001.hair
  expect_rc 2 "$hairgen" interpolate "$gust" --guides "$tmp/sim/g.####.hair" -o "$tmp/o/c.####.hair" \
    --frames 1-3 "${small[@]}"
  expect_err "g.0003.hair"
  user_file_intact
  for f in 0001 0002; do
    [ -f "$tmp/o/c.$f.hair" ] && [ ! -L "$tmp/o/c.$f.hair" ] || fail "finished frame $f is gone"
    expect_rc 0 "$hairgen" info "$tmp/o/c.$f.hair"
  done
  [ ! -e "$tmp/o/c.0003.hair" ] || fail "the failed frame was left"
  no_temporaries "$tmp"
  # --stats of the failed command names the frames that stay.
  expect_rc 2 "$hairgen" interpolate "$gust" --guides "$tmp/sim/g.####.hair" -o "$tmp/o2/c.####.hair" \
    --frames 1-3 "${small[@]}" --stats "$tmp/s.json"
  grep -q 'o2/c.0002.hair' "$tmp/s.json" || fail "--stats does not name the frames kept: $(cat "$tmp/s.json")"
  ;;
failed_simulation_links)
  # simulate fails at frame 4 (its name is taken by a folder); the caches of frames 1-3 stay, and the
  # links that had taken frame names point where they did, at what they did.
  expect_rc 0 "$hairgen" grow "$gust" -o "$tmp/g.hair" "${small[@]}"
  plant_links "$tmp/sim" g.0002.hair g.0003.hair
  mkdir "$tmp/sim/g.0004.hair"
  expect_rc 2 "$hairgen" simulate "$gust" --guides "$tmp/g.hair" -o "$tmp/sim/g.####.hair" \
    --set "Dynamics.Frames=1 6" "${small[@]}"
  expect_err "g.0004.hair: is a directory"
  user_file_intact
  for f in 0001 0002 0003; do
    [ -f "$tmp/sim/g.$f.hair" ] && [ ! -L "$tmp/sim/g.$f.hair" ] || fail "finished cache $f is gone"
  done
  # What stays is what a restart needs: frames 4-6 resume from frame 3's cache and equal one whole run.
  rmdir "$tmp/sim/g.0004.hair"
  expect_rc 0 "$hairgen" simulate "$gust" --guides "$tmp/g.hair" -o "$tmp/sim/g.####.hair" --frames 4-6 \
    --set "Dynamics.Frames=1 6" "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$gust" --guides "$tmp/g.hair" -o "$tmp/whole/g.####.hair" \
    --set "Dynamics.Frames=1 6" "${small[@]}"
  for f in 0001 0003 0006; do cmp "$tmp/sim/g.$f.hair" "$tmp/whole/g.$f.hair" || fail "frame $f differs"; done
  no_temporaries "$tmp"
  ;;
failed_shot_keeps_frames)
  # run on a shot fails at frame 3 (its preview's name is taken by a folder): every finished frame stays,
  # EXR, PNG and cache, and the user's file behind a frame link is untouched.
  plant_links "$tmp/run" beauty.0002.exr beauty.0001.png
  mkdir "$tmp/run/beauty.0003.png"
  expect_rc 2 "$hairgen" run "$gust" -o "$tmp/run" "${small[@]}" --set "Dynamics.Frames=1 4"
  user_file_intact
  for f in 0001 0002; do
    for file in beauty.$f.exr beauty.$f.png sim/guides.$f.hair; do
      [ -f "$tmp/run/$file" ] && [ ! -L "$tmp/run/$file" ] || fail "finished $file is gone"
    done
  done
  [ ! -e "$tmp/run/beauty.0003.exr" ] || fail "the failed frame's EXR was left"
  no_temporaries "$tmp"
  ;;
output_link)
  # One output named by a link: the link is replaced by the file (as mv does), the file it pointed to
  # is untouched, and a link to nowhere makes no folder. A folder on the way that is a link to nowhere
  # is refused before the work, and nothing is made through it.
  expect_rc 0 "$hairgen" grow "$gust" -o "$tmp/g.hair" "${small[@]}"
  plant_links "$tmp/o" a.hair b.hair
  expect_rc 0 "$hairgen" convert "$tmp/g.hair" "$tmp/o/a.hair" -q
  expect_rc 0 "$hairgen" convert "$tmp/g.hair" "$tmp/o/b.hair" -q
  user_file_intact
  cmp "$tmp/g.hair" "$tmp/o/a.hair" && cmp "$tmp/g.hair" "$tmp/o/b.hair" || fail "the outputs are not the guides"
  [ ! -L "$tmp/o/a.hair" ] && [ ! -L "$tmp/o/b.hair" ] || fail "a link named as the output is still a link"
  ln -s "$tmp/nowhere/deeper" "$tmp/o/folder"
  expect_rc 2 "$hairgen" grow "$gust" -o "$tmp/o/folder/g.hair" "${small[@]}"
  expect_err "o/folder: is a symbolic link to $tmp/nowhere/deeper, which does not exist"
  expect_rc 2 "$hairgen" run "$gust" -o "$tmp/o/folder/run" "${small[@]}" --no-render
  expect_err "which does not exist"
  user_file_intact
  no_temporaries "$tmp"
  ;;
frame_pattern_width)
  # A placeholder of any width numbers every frame: 33 #s give 33 digits (a 32-byte buffer once wrote
  # every frame into one file); a name too long for any file system is refused before the work.
  expect_rc 0 "$hairgen" grow "$gust" -o "$tmp/g.hair" "${small[@]}"
  for f in 0001 0002 0003; do cp "$tmp/g.hair" "$tmp/g.$f.hair"; done
  wide=$(printf '#%.0s' $(seq 33))
  expect_rc 0 "$hairgen" interpolate "$gust" --guides "$tmp/g.####.hair" -o "$tmp/w/c.$wide.hair" --frames 1-3 "${small[@]}"
  for f in 1 2 3; do
    [ -s "$tmp/w/c.$(printf '%033d' $f).hair" ] || fail "no frame $f of 33 digits: $(ls "$tmp/w")"
  done
  [ "$(ls "$tmp/w" | wc -l)" -eq 3 ] || fail "3 frames, not 3 files: $(ls "$tmp/w")"
  expect_rc 0 "$hairgen" interpolate "$gust" --guides "$tmp/g.%04d.hair" -o "$tmp/p/c.%040d.hair" --frames 2-3 "${small[@]}"
  [ -s "$tmp/p/c.$(printf '%040d' 3).hair" ] || fail "no frame 3 of %040d: $(ls "$tmp/p")"
  long=$(printf '#%.0s' $(seq 300))
  expect_rc 2 "$hairgen" interpolate "$gust" --guides "$tmp/g.####.hair" -o "$tmp/l/c.$long.hair" --frames 1-3 "${small[@]}"
  expect_err "a file name can have"
  [ ! -e "$tmp/l" ] || fail "a refused pattern made its folder"
  ;;
movie_odd_size)
  # A shot of 41x39 pixels: H.264 needs even sizes, so the movie is padded to 42x40; run succeeds.
  command -v ffprobe >/dev/null || skip "no ffmpeg here (scripts/setup.sh installs it)"
  expect_rc 0 "$hairgen" run "$gust" -o "$tmp/run" "${small[@]}" --set "Dynamics.Frames=1 3" --set "Render.Resolution=41 39"
  [ "$(frames_of "$tmp/run/beauty.mp4")" = 3 ] || fail "the movie does not hold the shot's 3 frames"
  [ "$(size_of "$tmp/run/beauty.mp4")" = "42,40" ] || fail "the movie is $(size_of "$tmp/run/beauty.mp4"), not 42x40"
  [ -s "$tmp/run/beauty.gif" ] || fail "no GIF"
  for f in 0001 0003; do [ -s "$tmp/run/beauty.$f.exr" ] || fail "frame $f is gone"; done
  ;;
movie_failing_ffmpeg)
  # An ffmpeg that fails: run keeps its frames, warns in one line naming the movie and ffmpeg's reason,
  # and succeeds (the frames are the shot); `movie`, whose product the movie is, fails with exit 1.
  mkdir "$tmp/bin"
  printf '#!/bin/sh\necho "frame size not supported by the encoder" >&2\nexit 1\n' > "$tmp/bin/ffmpeg"
  chmod +x "$tmp/bin/ffmpeg"
  PATH="$tmp/bin:$PATH" expect_rc 0 "$hairgen" run "$gust" -o "$tmp/run" "${small[@]}" --set "Dynamics.Frames=1 3"
  grep -q "warning: .*beauty.mp4.*frame size not supported by the encoder" "$tmp/err" ||
    fail "no warning naming the movie and ffmpeg's reason: $(cat "$tmp/err")"
  [ "$(grep -c . "$tmp/err")" -eq 1 ] || fail "more than one line on stderr: $(cat "$tmp/err")"
  for f in 0001 0002 0003; do
    for file in beauty.$f.exr beauty.$f.png sim/guides.$f.hair; do [ -s "$tmp/run/$file" ] || fail "$file is gone"; done
  done
  [ ! -e "$tmp/run/beauty.mp4" ] || fail "a movie from a failed ffmpeg"
  no_temporaries "$tmp"
  PATH="$tmp/bin:$PATH" expect_rc 1 "$hairgen" movie "$tmp/run/beauty.####.png" --frames 1-3 -o "$tmp/m.mp4"
  expect_err "m.mp4: ffmpeg failed (exit 1): frame size not supported by the encoder"
  [ ! -e "$tmp/m.mp4" ] || fail "movie left a file"
  no_temporaries "$tmp"
  ;;
movie_paths)
  # Paths ffmpeg reads as patterns, protocols or options: a folder with % and :, a name starting with -,
  # take:1.mp4. Each makes its movie.
  command -v ffprobe >/dev/null || skip "no ffmpeg here (scripts/setup.sh installs it)"
  weird="$tmp/shot 100%d:v1"
  expect_rc 0 "$hairgen" run "$gust" -o "$weird" "${small[@]}" --set "Dynamics.Frames=1 3"
  [ "$(frames_of "$weird/beauty.mp4")" = 3 ] || fail "run into '$weird' made no movie of 3 frames"
  [ -s "$weird/beauty.gif" ] || fail "run into '$weird' made no GIF"
  mkdir "$tmp/%03d"
  for f in 0001 0002 0003; do cp "$weird/beauty.$f.png" "$tmp/%03d/-b.$f.png"; done
  (cd "$tmp/%03d" && "$hairgen" movie --frames 1-3 --output=-take.mp4 --gif=take:1.gif -q -- "-b.####.png") ||
    fail "movie of -b.####.png to -take.mp4 failed"
  (cd "$tmp/%03d" && "$hairgen" movie "./-b.####.png" --frames 1-3 -o take:1.mp4 -q) ||
    fail "movie to take:1.mp4 failed"
  for m in -take.mp4 take:1.mp4; do
    [ "$(frames_of "$tmp/%03d/$m")" = 3 ] || fail "$m does not hold 3 frames"
  done
  [ -s "$tmp/%03d/take:1.gif" ] || fail "no take:1.gif"
  no_temporaries "$tmp"
  ;;
failed_command_restores)
  # A command that fails after writing over a file (its own input, a link) puts back what was there: a
  # failed command never costs a file that existed. And a FIFO no one reads, or a long name, as outputs.
  default="$src/configs/default/setup.txt"
  expect_rc 0 "$hairgen" grow "$default" -o "$tmp/g.hair" "${small[@]}"
  cp "$tmp/g.hair" "$tmp/g.orig"
  # convert in place, then its --stats cannot be written.
  expect_rc 1 "$hairgen" convert "$tmp/g.hair" "$tmp/g.hair" --quiet --stats /dev/full
  cmp "$tmp/g.hair" "$tmp/g.orig" || fail "a failed convert in place lost its input"
  # run that Loads and Saves the same coupe, then refuses its render.
  expect_rc 0 "$hairgen" interpolate "$default" --guides "$tmp/g.hair" -o "$tmp/mine.hair" "${small[@]}"
  cp "$tmp/mine.hair" "$tmp/mine.orig"
  expect_rc 2 "$hairgen" run "$default" -o "$tmp/run" --quiet --set Setup.Load=true \
    --set "Setup.LoadFile=$tmp/mine.hair" --set Setup.Save=true --set "Setup.SaveFile=$tmp/mine.hair" \
    --set "Render.Resolution=16384 16384"
  cmp "$tmp/mine.hair" "$tmp/mine.orig" || fail "a failed run lost the coupe it loaded and saved over"
  # A sequence converted in place whose second frame is bad: the first is put back (convert keeps no
  # frame of a failed sequence).
  expect_rc 0 "$hairgen" convert "$tmp/g.hair" "$tmp/f.0001.ply" --quiet
  cp "$tmp/f.0001.ply" "$tmp/f.orig"
  head -c 100 "$tmp/f.0001.ply" >"$tmp/f.0002.ply"
  expect_rc 2 "$hairgen" convert "$tmp/f.####.ply" "$tmp/f.####.ply" --frames 1-2 --ascii --quiet
  cmp "$tmp/f.0001.ply" "$tmp/f.orig" || fail "a failed convert in place lost frame 1"
  # An output name that is a link: the link is put back, pointing where it did; its file untouched.
  plant_links "$tmp/l" c.hair c2.hair
  expect_rc 1 "$hairgen" convert "$tmp/g.hair" "$tmp/l/c.hair" --quiet --stats /dev/full
  [ "$(readlink "$tmp/l/c.hair")" = "$tmp/keep/notes.txt" ] || fail "the link named as the output was not put back"
  user_file_intact
  # movie onto one of its frames, or a GIF that is a folder: refused before ffmpeg runs.
  expect_rc 0 "$hairgen" render "$default" --hair "$tmp/mine.hair" -o "$tmp/b.0001.exr" --preview "$tmp/b.0001.png" "${small[@]}"
  cp "$tmp/b.0001.png" "$tmp/b.0002.png"
  cp "$tmp/b.0001.png" "$tmp/b.orig"
  expect_rc 2 "$hairgen" movie "$tmp/b.####.png" --frames 1-2 -o "$tmp/b.0001.png" --quiet
  expect_err "is frame 1 of the movie"
  mkdir "$tmp/adir"
  expect_rc 2 "$hairgen" movie "$tmp/b.####.png" --frames 1-2 -o "$tmp/m.mp4" --gif "$tmp/adir" --quiet
  expect_err "is a directory"
  cmp "$tmp/b.0001.png" "$tmp/b.orig" || fail "movie wrote over its frame"
  [ ! -e "$tmp/m.mp4" ] || fail "a refused movie was written"
  # A FIFO that no process opens to read: an error after 10 s, not a wait for ever.
  mkfifo "$tmp/fifo.ply"
  expect_rc 1 timeout 60 "$hairgen" convert "$tmp/g.hair" "$tmp/fifo.ply" --quiet
  expect_err "a FIFO (a named pipe) that no process opened to read within 10 s"
  # A name of 250 bytes (the folder entry's limit is 255): written as any other.
  long="$tmp/$(printf 'x%.0s' $(seq 1 245)).hair"
  expect_rc 0 "$hairgen" convert "$tmp/g.hair" "$long" --quiet
  cmp "$long" "$tmp/g.hair" || fail "the long-named output differs"
  no_temporaries "$tmp"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
