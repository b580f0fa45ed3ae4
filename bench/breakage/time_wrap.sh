#!/bin/sh
# Runs liggghts-mill under /usr/bin/time for the impact and in-mill decks
# (the lump builder's deck runs as it is) and appends "deck user_s sys_s" to
# $TW_OUT. Use it as MILL_LIGGGHTS=bench/breakage/time_wrap.sh
# TW_EXE=build/bin/liggghts-mill TW_OUT=/tmp/times.txt orchestrate ...
case "$*" in
  *impact.in.tmpl*|*in_mill.in.tmpl*)
    /usr/bin/time -f "$PWD %U %S" -a -o "$TW_OUT" "$TW_EXE" "$@" ;;
  *) exec "$TW_EXE" "$@" ;;
esac
