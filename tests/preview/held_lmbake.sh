#!/bin/sh
# lmbake as preview_watch.mjs's watch runs it: the watch's bakes, held at points the test names,
# so that each picture the watch shows is on screen for the test to read however loaded the
# machine (a final bake's direct stage can follow its quick look by 0.2 s).
#   LMBAKE_REAL: the lmbake to run; LMBAKE_HOLD_DIR: a folder of hold files:
#   final     while it exists, a final bake (--stages-out without --quick) waits before it starts;
#   STAGE     (direct, bounces) once a final bake says "stages: STAGE written to ...", it is
#             stopped (SIGSTOP) before the watch reads that line, and goes on once the file is gone.
# Anything else runs lmbake as it is.
set -u
case " $* " in
  *" --quick "*) exec "$LMBAKE_REAL" "$@" ;;
  *" --stages-out "*) ;;
  *) exec "$LMBAKE_REAL" "$@" ;;
esac
hold=$LMBAKE_HOLD_DIR
while [ -e "$hold/final" ]; do sleep 0.02; done
fifo=$hold/stdout.$$
rm -f "$fifo"
mkfifo "$fifo"
"$LMBAKE_REAL" "$@" >"$fifo" &
pid=$!
trap 'kill -CONT $pid 2>/dev/null; kill -TERM $pid 2>/dev/null; exit 143' TERM INT
while IFS= read -r line; do
  case $line in
    "stages: "*" written to "*)
      stage=${line#stages: }
      stage=${stage%% *}
      if [ -e "$hold/$stage" ]; then
        kill -STOP $pid
        printf '%s\n' "$line"
        while [ -e "$hold/$stage" ]; do sleep 0.02; done
        kill -CONT $pid
        continue
      fi ;;
  esac
  printf '%s\n' "$line"
done <"$fifo"
wait $pid
rc=$?
rm -f "$fifo"
exit $rc
