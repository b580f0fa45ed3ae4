#!/bin/sh
# Runs liggghts-mill under valgrind's callgrind for the in-mill deck only
# (other decks, such as the lump builder's, run as they are). Use it as
#   MILL_LIGGGHTS=bench/in_mill/callgrind_wrap.sh CG_EXE=build/bin/liggghts-mill \
#   CG_OUT=/tmp/in_mill.callgrind DURATION=2.5e-4 LEAD_TIME=5e-5 bench/in_mill/run.sh
# then `callgrind_annotate /tmp/in_mill.callgrind | grep FixImpactRecorder`.
case "$*" in
  *in_mill.in.tmpl*) exec valgrind --tool=callgrind --callgrind-out-file="$CG_OUT" "$CG_EXE" "$@" ;;
  *) exec "$CG_EXE" "$@" ;;
esac
