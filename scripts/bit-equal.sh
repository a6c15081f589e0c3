#!/usr/bin/env bash
# Exports the visibility of the default compare set (and of the specs in $EXTRA, run as a second
# compare) on every built-in scene and light with two shadowlab binaries and compares them byte
# for byte: the check that a refactor changed no result.
# Usage: scripts/bit-equal.sh BEFORE_BIN AFTER_BIN [OUT_DIR] [SIZE] [FRAMES]
# AFTER_BIN '-' only exports BEFORE_BIN's; KEEP_BEFORE=1 reuses BEFORE_BIN's exports in OUT_DIR.
set -euo pipefail
before=$1 after=$2 out=${3:-/tmp/shadowlab-bit-equal} size=${4:-256x256} frames=${5:-2}
extra=${EXTRA:-"sdsm sdsm:delayed=true virtual virtual:resolution_bias=-1.5 csm:tighten=false iasm:fit=fixed"}
mkdir -p "$out"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp}
scenes=$("$before" scenes | awk '/^Built-in scenes/{b=1;next} b&&/^  [a-z]/{print $1} b&&/^$/{exit}')
[ -n "$scenes" ] || { echo "no built-in scenes listed" >&2; exit 1; }
status=0
for s in $scenes; do
    for l in 0 1 2 3; do
        for set in default $extra; do
            tag="$s-$l-${set//[:=,]/_}"
            args=(); [ "$set" != default ] && args=(-t "$set")
            for which in before after; do
                bin=$before; [ $which = after ] && bin=$after
                [ $which = after ] && [ ! -d "$out/before-$tag" ] && break
                [ $which = before ] && [ "${KEEP_BEFORE:-0}" = 1 ] && [ -f "$out/before-$tag.done" ] && continue
                [ $which = before ] && [ "${KEEP_BEFORE:-0}" = 1 ] && [ -f "$out/before-$tag.none" ] && break
                [ "$bin" = - ] && continue
                rm -rf "$out/$which-$tag"
                if ! "$bin" compare --scene "$s" --light "$l" --size "$size" --frames "$frames" --repeat 1 --export -q \
                    "${args[@]}" --out "$out/$which-$tag" >"$out/$which-$tag.log" 2>&1; then
                    rm -rf "$out/$which-$tag"
                    [ $which = before ] && touch "$out/before-$tag.none"
                    break
                fi
                [ $which = before ] && touch "$out/before-$tag.done"
            done
            [ "$after" = - ] && continue
            [ -d "$out/before-$tag" ] || continue
            if [ ! -d "$out/after-$tag" ]; then echo "$tag: after failed ($(tail -1 "$out/after-$tag.log"))"; status=1; continue; fi
            n=0; bad=0
            for f in "$out/before-$tag"/visibility/*.npy; do
                g="$out/after-$tag/visibility/$(basename "$f")"
                n=$((n + 1))
                if ! cmp -s "$f" "$g"; then echo "$tag: $(basename "$f" .npy) differs"; bad=$((bad + 1)); status=1; fi
            done
            echo "$tag: $((n - bad)) of $n visibility exports bit-equal"
        done
    done
done
exit $status
