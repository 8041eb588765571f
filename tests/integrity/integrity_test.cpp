// Message integrity of the bus (service/integrity.hpp, docs/security.md): HMAC-SHA256 against
// RFC 4231's test vectors, signing and verification of encoded messages, the key file rules,
// conflict detection (StepLedger, differing_fields, Node::admit) and the foreign-run filter of
// the Bus, over LCM's in-process transport memq://.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../../examples/c/fd_sign.h"
#include "feeddrive/service/bus.hpp"
#include "feeddrive/service/cli.hpp"
#include "feeddrive/service/integrity.hpp"
#include "feeddrive/service/node.hpp"

namespace feeddrive::service {
namespace {

std::string hex(const std::uint8_t* d, std::size_t n) {
  std::string s;
  char b[3];
  for (std::size_t i = 0; i < n; ++i) {
    std::snprintf(b, sizeof b, "%02x", d[i]);
    s += b;
  }
  return s;
}

std::string hmac_hex(const std::string& key, const std::string& data) {
  const auto m = hmac_sha256(key, reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
  return hex(m.data(), m.size());
}

// RFC 4231, "Identifiers and Test Vectors for HMAC-SHA-224, -256, -384, and -512", section 4,
// HMAC-SHA-256 of test cases 1, 2, 3 and 6 (a key longer than the block size).
TEST(Hmac, Rfc4231TestVectors) {
  EXPECT_EQ(hmac_hex(std::string(20, '\x0b'), "Hi There"),
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7");
  EXPECT_EQ(hmac_hex("Jefe", "what do ya want for nothing?"),
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
  EXPECT_EQ(hmac_hex(std::string(20, '\xaa'), std::string(50, '\xdd')),
            "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe");
  EXPECT_EQ(hmac_hex(std::string(131, '\xaa'), "Test Using Larger Than Block-Size Key - Hash Key First"),
            "60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54");
}

control_command_t command(std::int64_t seq, double u) {
  control_command_t c{};
  c.run_id = 42;
  c.seq = seq;
  c.t = 1e-4 * static_cast<double>(seq);
  c.u = u;
  c.u_unsaturated = u;
  c.sliding = std::nan("");
  c.z_estimate = std::nan("");
  return c;
}

// The encoding of `c` with room for a mac: mac_size = 0 encoded, then 32 more bytes.
std::vector<std::uint8_t> encode_for_signing(const control_command_t& c) {
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(c.getEncodedSize()) + MessageAuth::kMacSize);
  c.encode(buf.data(), 0, c.getEncodedSize());
  return buf;
}

// sign() writes mac_size = 32 and HMAC-SHA256(key, channel || NUL || encoding up to mac_size),
// computed here independently with the one-shot hmac_sha256; the result decodes as a message
// carrying that mac, and verify() accepts it only unchanged and on its channel.
TEST(MessageAuth, SignsChannelAndEncodingAndVerifies) {
  const std::string key = "0123456789abcdef0123456789abcdef";
  MessageAuth auth(key);
  const control_command_t c = command(7, 0.25);
  std::vector<std::uint8_t> buf = encode_for_signing(c);
  auth.sign("FD_CMD", buf.data(), buf.size());

  std::vector<std::uint8_t> input = {'F', 'D', '_', 'C', 'M', 'D', 0};
  input.insert(input.end(), buf.begin(), buf.end() - MessageAuth::kTrailer);
  const auto expect = hmac_sha256(key, input.data(), input.size());
  EXPECT_EQ(hex(buf.data() + buf.size() - 32, 32), hex(expect.data(), 32));

  control_command_t back{};
  ASSERT_EQ(back.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  EXPECT_EQ(back.mac_size, 32);
  EXPECT_EQ(back.seq, 7);
  EXPECT_EQ(back.run_id, 42);

  EXPECT_TRUE(auth.verify("FD_CMD", buf.data(), buf.size()));
  EXPECT_FALSE(auth.verify("FD_STATE", buf.data(), buf.size())) << "the channel is signed";
  EXPECT_FALSE(MessageAuth("another key of 32 bytes .......").verify("FD_CMD", buf.data(), buf.size()));
  for (std::size_t i : {std::size_t{0}, std::size_t{9}, std::size_t{20}, buf.size() - 1}) {
    std::vector<std::uint8_t> bad = buf;
    bad[i] ^= 0x01;  // fingerprint, run_id, u, mac
    EXPECT_FALSE(auth.verify("FD_CMD", bad.data(), bad.size())) << "byte " << i;
  }
  // An unsigned message (mac_size = 0) and a truncated one are rejected.
  std::vector<std::uint8_t> plain(static_cast<std::size_t>(c.getEncodedSize()));
  c.encode(plain.data(), 0, static_cast<int>(plain.size()));
  EXPECT_FALSE(auth.verify("FD_CMD", plain.data(), plain.size()));
  EXPECT_FALSE(auth.verify("FD_CMD", buf.data(), 10));
}

// The C example for external programs (examples/c/fd_sign.h) signs exactly as the processes do,
// and verifies what they sign.
TEST(MessageAuth, CExampleSignsLikeTheProcesses) {
  const std::string key = "0123456789abcdef0123456789abcdef";
  const auto* k = reinterpret_cast<const unsigned char*>(key.data());
  const control_command_t c = command(11, -0.75);
  std::vector<std::uint8_t> ours = encode_for_signing(c);
  MessageAuth(key).sign("FD_CMD", ours.data(), ours.size());
  std::vector<std::uint8_t> theirs = encode_for_signing(c);
  ASSERT_EQ(fd_sign(k, static_cast<int>(key.size()), "FD_CMD", theirs.data(), theirs.size() - 32), theirs.size());
  EXPECT_EQ(theirs, ours);
  EXPECT_EQ(fd_verify(k, static_cast<int>(key.size()), "FD_CMD", ours.data(), ours.size()), 1);
  EXPECT_EQ(fd_verify(k, static_cast<int>(key.size()), "FD_REF", ours.data(), ours.size()), 0);
  ours[20] ^= 0x40;
  EXPECT_EQ(fd_verify(k, static_cast<int>(key.size()), "FD_CMD", ours.data(), ours.size()), 0);
}

TEST(DifferingFields, NamesEveryDifferentFieldAndNothingElse) {
  const control_command_t a = command(3, 0.5);
  EXPECT_EQ(differing_fields(a, a), "") << "NaN diagnostics compare bit for bit";
  control_command_t b = a;
  b.u = 3.0;
  b.u_unsaturated = 3.0;
  b.run_id = 7;  // not compared: checked before
  EXPECT_EQ(differing_fields(a, b), "u, u_unsaturated");

  drive_state_t s{};
  s.seq = 5;
  s.truth.x = 0.1;
  drive_state_t s2 = s;
  s2.truth.x = 0.2;
  s2.previous.u = 1.0;
  EXPECT_EQ(differing_fields(s, s2), "truth.x, previous.u");

  reference_t r{};
  r.seq = 16;
  reference_t r2 = r;
  r2.position = 1.0;
  EXPECT_EQ(differing_fields(r, r2), "position");
}

TEST(StepLedger, NewSameConflictAndReuse) {
  StepLedger<control_command_t> ledger(4);
  std::string diff;
  using Seen = StepLedger<control_command_t>::Seen;
  EXPECT_EQ(ledger.admit(0, command(0, 0.5)), Seen::kNew);
  EXPECT_EQ(ledger.admit(0, command(0, 0.5)), Seen::kSame) << "a re-publication is harmless";
  EXPECT_EQ(ledger.admit(0, command(0, 3.0), &diff), Seen::kConflict);
  EXPECT_EQ(diff, "u, u_unsaturated");
  EXPECT_EQ(ledger.admit(0, command(0, 0.5)), Seen::kSame) << "the first one stays recorded";
  // Steps 1..4 fill the 4 slots; step 0's slot now holds step 4: step 0 is not remembered.
  for (std::int64_t k = 1; k <= 4; ++k) EXPECT_EQ(ledger.admit(k, command(k, 0.5)), Seen::kNew);
  EXPECT_EQ(ledger.admit(0, command(0, 3.0)), Seen::kNew);
}

NodeOptions memq_options(std::int64_t run_id) {
  NodeOptions opt;
  opt.lcm_url = "memq://";
  opt.run_id = run_id;
  opt.quiet = true;
  return opt;
}

// The default policy fails the run with one line naming channel, step and fields; keep-first
// drops the second message and counts it.
TEST(NodeAdmit, ConflictFailsByDefaultOrKeepsTheFirst) {
  Node fail_node("controller", memq_options(1));
  StepLedger<control_command_t> ledger;
  EXPECT_TRUE(fail_node.admit(ledger, "FD_CMD", 12, command(12, 0.5)));
  EXPECT_TRUE(fail_node.admit(ledger, "FD_CMD", 12, command(12, 0.5)));
  try {
    fail_node.admit(ledger, "FD_CMD", 12, command(12, 3.0));
    FAIL() << "no RunFailure";
  } catch (const RunFailure& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("conflict on FD_CMD step 12"), std::string::npos) << what;
    EXPECT_NE(what.find("control_command_t"), std::string::npos) << what;
    EXPECT_NE(what.find("u, u_unsaturated differ"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line";
  }
  EXPECT_EQ(fail_node.conflicts, 1);

  NodeOptions opt = memq_options(1);
  opt.on_conflict = ConflictPolicy::kKeepFirst;
  Node keep_node("plant", opt);
  StepLedger<control_command_t> ledger2;
  EXPECT_TRUE(keep_node.admit(ledger2, "FD_CMD", 3, command(3, 0.5)));
  EXPECT_FALSE(keep_node.admit(ledger2, "FD_CMD", 3, command(3, 3.0)));
  EXPECT_EQ(keep_node.conflicts, 1);
  // --on-conflict's names are its one table (fields::enum_names): read, written, listed.
  EXPECT_EQ(fields::enum_from_name<ConflictPolicy>("keep-first"), ConflictPolicy::kKeepFirst);
  EXPECT_STREQ(fields::enum_name(ConflictPolicy::kFail), "fail");
  EXPECT_THROW(fields::enum_from_name<ConflictPolicy>("ignore"), std::invalid_argument);
}

// An observer's failure never stops a run: a "monitor-attached" (or any role outside the run)
// announcing "failed" is heard and kept as a peer, but only the run's own roles (plant,
// controller, trajectory, monitor) make check_peers() throw. Over memq://, where the node hears
// what its own bus publishes; the CI failure this guards against: an attached monitor that lost
// a datagram under load failed, and the whole run stopped with it.
TEST(NodePeers, AnObserversFailureDoesNotStopTheRun) {
  Node plant("plant", memq_options(1));
  const auto failed = [&](const std::string& role) {
    process_status_t m{};
    m.role = role;
    m.state = "failed";
    m.seq = 6860;
    m.message = "step 6860 incomplete";
    plant.bus().publish(plant.channels().status, m);
    plant.bus().poll(std::chrono::milliseconds(10));
  };
  failed("monitor-attached");
  ASSERT_NE(plant.peer("monitor-attached"), nullptr) << "heard";
  EXPECT_EQ(plant.peer("monitor-attached")->state, "failed");
  EXPECT_NO_THROW(plant.check_peers());
  EXPECT_FALSE(is_run_role("monitor-attached"));
  for (const char* role : {"plant", "controller", "trajectory", "monitor"}) EXPECT_TRUE(is_run_role(role)) << role;
  failed("controller");
  try {
    plant.check_peers();
    FAIL() << "a failed controller must stop the run";
  } catch (const RunFailure& e) {
    EXPECT_STREQ(e.what(), "controller failed at step 6860: step 6860 incomplete");
  }
}

// Over memq:// (one LCM instance hears its own messages): a message of another run is counted
// and not dispatched; before the run is known nothing is dispatched; join_first_seen() joins.
TEST(BusRunIdentity, ForeignMessagesAreCountedAndIgnored) {
  Bus bus("memq://");
  std::vector<std::int64_t> got;
  bus.subscribe<control_command_t>("T_CMD", [&](const control_command_t& m, std::int64_t) { got.push_back(m.seq); });
  bus.publish("T_CMD", command(0, 0.5));  // run id 0 (not set): the bus has not joined a run
  bus.poll(std::chrono::milliseconds(10));
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(bus.foreign(), 0) << "before joining nothing counts as foreign";

  bus.set_run_id(5);
  bus.publish("T_CMD", command(1, 0.5));  // stamped with run 5
  bus.poll(std::chrono::milliseconds(10));
  EXPECT_EQ(got, std::vector<std::int64_t>{1});

  bus.set_run_id(7);  // a message of run 7 ...
  bus.publish("T_CMD", command(2, 0.5));
  bus.set_run_id(5);  // ... heard by a process of run 5
  bus.poll(std::chrono::milliseconds(10));
  EXPECT_EQ(got, std::vector<std::int64_t>{1});
  EXPECT_EQ(bus.foreign(), 1);

  Bus attached("memq://");
  attached.join_first_seen();
  std::vector<std::int64_t> seen;
  attached.subscribe<control_command_t>("T_CMD",
                                        [&](const control_command_t& m, std::int64_t) { seen.push_back(m.run_id); });
  attached.publish("T_CMD", command(0, 0.5));  // not joined: stamped with run id 0
  EXPECT_FALSE(attached.run_known());
  attached.poll(std::chrono::milliseconds(10));
  EXPECT_TRUE(attached.run_known()) << "joined the run of the first message";
  EXPECT_EQ(attached.run_id(), 0);
  EXPECT_EQ(seen.size(), 1u);
}

// A keyed bus rejects unsigned messages and messages signed with another key before decoding,
// and accepts its own (signed at publish).
TEST(BusAuthentication, RejectsUnsignedAndForeignKeys) {
  Bus bus("memq://");
  bus.set_run_id(3);
  int n = 0;
  bus.subscribe<control_command_t>("T_CMD", [&](const control_command_t&, std::int64_t) { ++n; });
  bus.publish("T_CMD", command(0, 0.5));  // unsigned: no key yet
  bus.set_auth("the deployment's key, 32 bytes..");
  bus.poll(std::chrono::milliseconds(10));
  EXPECT_EQ(n, 0);
  EXPECT_EQ(bus.unauthenticated(), 1);
  bus.publish("T_CMD", command(1, 0.5));  // signed
  bus.poll(std::chrono::milliseconds(10));
  EXPECT_EQ(n, 1);
  bus.set_auth("another key, also 32 bytes......");
  bus.poll(std::chrono::milliseconds(10));
  bus.set_auth("the deployment's key, 32 bytes..");
  bus.publish("T_CMD", command(2, 0.5));
  bus.set_auth("another key, also 32 bytes......");
  bus.poll(std::chrono::milliseconds(10));
  EXPECT_EQ(n, 1);
  EXPECT_EQ(bus.unauthenticated(), 2);
}

TEST(KeyFile, OnlyTheOwnersAndOfAKeysLength) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("fd-key-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "key").string();
  { std::ofstream(path) << "0123456789abcdef0123456789abcdef"; }
  ::chmod(path.c_str(), 0644);
  try {
    read_key_file(path);
    FAIL() << "a world-readable key was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mode 0644"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("chmod 600"), std::string::npos) << e.what();
  }
  ::chmod(path.c_str(), 0640);
  EXPECT_THROW(read_key_file(path), std::invalid_argument) << "group-readable";
  ::chmod(path.c_str(), 0600);
  EXPECT_EQ(read_key_file(path), "0123456789abcdef0123456789abcdef");
  { std::ofstream(path) << "short"; }
  EXPECT_THROW(read_key_file(path), std::invalid_argument);
  EXPECT_THROW(read_key_file((dir / "missing").string()), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

// A key behind a symlink (as Kubernetes and Docker mount secrets: key -> ..data/key) is read,
// and the checks are the target's: a link to a group-readable file is refused, naming the target.
TEST(KeyFile, ASymlinkIsFollowedAndItsTargetChecked) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("fd-key-link-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "..data");
  const std::string target = (dir / "..data" / "key").string();
  { std::ofstream(target) << "0123456789abcdef0123456789abcdef"; }
  ::chmod(target.c_str(), 0600);
  const std::string link = (dir / "key").string();
  std::filesystem::create_symlink("..data/key", link);
  EXPECT_EQ(read_key_file(link), "0123456789abcdef0123456789abcdef");
  ::chmod(target.c_str(), 0644);
  try {
    read_key_file(link);
    FAIL() << "a link to a world-readable key was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a link to " + std::filesystem::canonical(target).string()), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("mode 0644"), std::string::npos) << e.what();
  }
  std::filesystem::remove(target);
  try {
    read_key_file(link);
    FAIL() << "a dangling link was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a link to a missing file"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace feeddrive::service

namespace feeddrive::service {
namespace {

// The run's scenario hash (run_info_t.scenario_hash, --scenario-hash) covers the tables the file
// names: a waypoints CSV swapped while the run starts is refused as the file itself would be
// (issue 19's review). A scenario without tables keeps its plain SHA-256 (the launcher's hash of
// older runs is unchanged).
TEST(ScenarioHash, CoversTheTablesItNames) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("fd-hash-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string yaml =
      "name: h\nduration: 0.01\ncontrol_period: 1.0e-3\ncontroller: {type: cascade}\n"
      "reference: {type: waypoints, file: w.csv}\n";
  { std::ofstream(dir / "s.yaml") << yaml; }
  { std::ofstream(dir / "w.csv") << "t,x\n0,0\n0.005,1e-4\n0.01,1e-4\n"; }
  const std::string path = (dir / "s.yaml").string();
  NodeOptions opt;
  const std::string h1 = load_run_scenario(path, opt).sha256;
  EXPECT_NE(h1, sha256_hex(yaml)) << "the table is part of the hash";
  EXPECT_EQ(load_run_scenario(path, opt).sha256, h1) << "the same files, the same hash";
  { std::ofstream(dir / "w.csv") << "t,x\n0,0\n0.005,2e-4\n0.01,2e-4\n"; }
  opt.scenario_hash = h1;
  try {
    load_run_scenario(path, opt);
    FAIL() << "a swapped waypoints table passed the launcher's hash";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a table it names, changed"), std::string::npos) << e.what();
  }
  const std::string plain =
      "name: p\nduration: 0.01\ncontrol_period: 1.0e-3\ncontroller: {type: cascade}\n"
      "reference: {type: step, amplitude: 1.0e-4}\n";
  { std::ofstream(dir / "plain.yaml") << plain; }
  EXPECT_EQ(load_run_scenario((dir / "plain.yaml").string(), NodeOptions{}).sha256, sha256_hex(plain));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace feeddrive::service
