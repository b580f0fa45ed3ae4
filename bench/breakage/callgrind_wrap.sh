#!/bin/bash
# Runs liggghts-mill under valgrind's callgrind for the impact deck only, cut
# short: t_end and the chunk (check_time) set to CG_TIME seconds of simulated
# time (the fixed-step deck then runs two such chunks; the lump builder's
# deck runs as it is). CG_OPTS: more valgrind options. Use it as
#   MILL_LIGGGHTS=$PWD/bench/breakage/callgrind_wrap.sh CG_EXE=$PWD/build/bin/liggghts-mill \
#   CG_OUT=/tmp/bond.callgrind CG_TIME=6.6e-5 CG_OPTS="--cache-sim=yes" \
#   build/bin/orchestrate --case bench/breakage/reference_impact_4ms.yaml --stage breakage --output DIR
# (the job then holds a short impact's results, which do not matter; the
# callgrind file is what counts). The command line is kept in $CG_OUT.cmd.
case "$*" in
  *impact.in.tmpl*)
    args=()
    while [ $# -gt 0 ]; do
      if [ "$1" = "-var" ] && { [ "$2" = "t_end" ] || [ "$2" = "check_time" ]; }; then
        args+=("$1" "$2" "$CG_TIME")
        shift 3
      else
        args+=("$1")
        shift
      fi
    done
    # the orchestrator leaves check_time (the chunk) at the deck's default
    case " ${args[*]} " in *" check_time "*) ;; *) args+=(-var check_time "$CG_TIME") ;; esac
    printf '%q ' "$CG_EXE" "${args[@]}" > "$CG_OUT.cmd"
    # shellcheck disable=SC2086
    exec valgrind --tool=callgrind --dump-instr=yes $CG_OPTS --callgrind-out-file="$CG_OUT" \
      "$CG_EXE" "${args[@]}" ;;
  *) exec "$CG_EXE" "$@" ;;
esac
