#!/usr/bin/env bash
# lcm-spy decodes our channels: the build's jar of the types (lcm-gen --java + javac, built only
# when a JDK was found) must decode every message a real run publishes. lcm-spy finds a class by
# the message's 8-byte fingerprint among the LCM types on its class path; this test does the same
# with the jar and LCM's own log reader (/usr/share/java/lcm.jar), on a log of a short run
# recorded by the stock lcm-logger. Without a JDK the jar is not built and the test says so.
source "$(dirname "$0")/lib.sh" "$@"
JAR=$BUILD/lcmtypes/feeddrive_lcmtypes.jar
LCM_JAR=/usr/share/java/lcm.jar
command -v javac >/dev/null && command -v java >/dev/null ||
  skip "no JDK (javac): the lcm-spy jar is not built; install one (Debian: default-jdk-headless) and rebuild"
[ -f "$LCM_JAR" ] || skip "$LCM_JAR missing (Debian package liblcm-java, scripts/install-deps.sh)"
[ -f "$JAR" ] || fail "$JAR not built although javac exists (re-run cmake: lcmtypes/CMakeLists.txt looks for a JDK)"
jar_list=$(jar tf "$JAR")
for t in "$SRC"/lcmtypes/*.lcm; do
  n=$(basename "$t" .lcm)
  printf '%s\n' "$jar_list" | grep -qx "feeddrive/$n.class" || fail "$JAR has no feeddrive/$n.class"
done

scen=$SRC/tests/service/scenarios/short_jerk.yaml
lcm-logger --lcm-url="$URL" --channel='SPY_.*' --force "$LOGDIR/run.lcmlog" 2> "$TMP/logger.err" & lg=$!
wait_on_bus $lg
timeout 120 feeddrive-launch "$scen" --out "$TMP/mp" --no-plots -q --prefix SPY --lcm-url "$URL"
stop_logger $lg "$LOGDIR/run.lcmlog" SPY  # once it has the whole run (lib.sh)

mkdir -p "$TMP/java"
cat > "$TMP/java/SpyDecode.java" <<'JAVA'
import java.io.*;
import java.util.*;
import java.util.zip.*;
import lcm.logging.Log;
import lcm.lcm.LCMEncodable;

// Decodes every event of an LCM log as lcm-spy would: by fingerprint, among the jar's types.
public class SpyDecode {
  public static void main(String[] a) throws Exception {
    Map<Long, Class<?>> byFingerprint = new HashMap<>();
    try (ZipFile z = new ZipFile(a[0])) {
      for (Enumeration<? extends ZipEntry> e = z.entries(); e.hasMoreElements();) {
        String n = e.nextElement().getName();
        if (!n.endsWith(".class")) continue;
        Class<?> c = Class.forName(n.substring(0, n.length() - 6).replace('/', '.'));
        if (LCMEncodable.class.isAssignableFrom(c))
          byFingerprint.put(c.getField("LCM_FINGERPRINT").getLong(null), c);
      }
    }
    Log log = new Log(a[1], "r");
    Map<String, Integer> counts = new TreeMap<>();
    int unknown = 0, markers = 0;
    try {
      for (;;) {
        Log.Event ev = log.readNext();
        // The test's flush markers (lib.sh, stop_logger): 5 raw bytes, no part of the contract.
        if (ev.channel.endsWith("_TEST_FLUSH")) { markers++; continue; }
        long fp = new DataInputStream(new ByteArrayInputStream(ev.data)).readLong();
        Class<?> c = byFingerprint.get(fp);
        if (c == null) { unknown++; System.err.println("no type for a message on " + ev.channel); continue; }
        c.getConstructor(byte[].class).newInstance((Object) ev.data);  // decodes, throws if it cannot
        counts.merge(ev.channel + " " + c.getSimpleName(), 1, Integer::sum);
      }
    } catch (EOFException end) {
    }
    System.out.println(counts + (markers > 0 ? " and " + markers + " flush markers" : ""));
    System.exit(unknown == 0 && !counts.isEmpty() ? 0 : 1);
  }
}
JAVA
javac -nowarn -cp "$JAR:$LCM_JAR" -d "$TMP/java" "$TMP/java/SpyDecode.java" 2> "$TMP/javac.err" ||
  { cat "$TMP/javac.err" >&2; fail "javac failed on the decoder"; }
out=$(timeout 120 java -cp "$TMP/java:$JAR:$LCM_JAR" SpyDecode "$JAR" "$LOGDIR/run.lcmlog") ||
  { echo "$out" >&2; fail "the jar does not decode every message of the run"; }
for ch in SPY_STATE SPY_CMD SPY_REF SPY_STATUS SPY_SUMMARY SPY_INFO; do
  printf '%s\n' "$out" | grep -q "$ch " || fail "no decoded message on $ch: $out"
done
pass "every logged message decodes with $JAR, as lcm-spy would: $out"
# The monitor's own log (feeddrive-launch --lcm-log) reads with LCM's Java log reader too (what
# lcm-logplayer-gui and lcm-spy's tools use).
timeout 120 feeddrive-launch "$scen" --out "$TMP/mp2" --no-plots -q --prefix SPY --lcm-url "$URL" --lcm-log "$LOGDIR/mon.lcmlog"
out=$(timeout 120 java -cp "$TMP/java:$JAR:$LCM_JAR" SpyDecode "$JAR" "$LOGDIR/mon.lcmlog") ||
  { echo "$out" >&2; fail "the jar does not decode every message of the monitor's log"; }
for ch in SPY_STATE SPY_CMD SPY_REF SPY_STATUS SPY_INFO; do
  printf '%s\n' "$out" | grep -q "$ch " || fail "no decoded message on $ch in the monitor's log: $out"
done
pass "the monitor's --lcm-log decodes with LCM's Java log reader: $out"
pass "start the spy with: CLASSPATH=$JAR lcm-spy --lcm-url='$URL'"
