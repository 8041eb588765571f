#!/usr/bin/env lua5.2
--[[
feeddrive external controller in Lua 5.2 (Debian: lua5.2, liblcm-lua; LCM 1.3.1).

It takes the "controller" role of a lockstep run started with
    build/bin/feeddrive-launch SCENARIO --out DIR --external controller
and follows the same message protocol as build/bin/feeddrive-controller
(service/src/controller_node.cpp). See docs/external-controllers.md and examples/lua/README.md.

Channels (<P> = --prefix, default FD):
  <P>_STATE   drive_state_t      from the plant, one per step k (repeated until command k comes)
  <P>_REF     reference_block_t  from the trajectory: 16 reference_t, up to 256 steps ahead
  <P>_CMD     control_command_t  published here, one per step
  <P>_STATUS  process_status_t   heartbeats of every process (this one: role "controller")
  <P>_RESEND  resend_request_t   "please re-publish message seq of channel C"

Protocol:
  * drive_state_t k, not answered yet: wait until reference_t k is known too, then compute u and
    publish control_command_t {seq = k, t = state.t, u, u_unsaturated, sliding, z_estimate} --
    exactly once per step. The encoded message is remembered.
  * drive_state_t k repeated after k was answered (the command got lost): re-publish the
    remembered command k, byte for byte. The controller is never run twice for a step.
  * state k there but reference k missing for ~2 ms (resend interval): publish resend_request_t
    {requester = "controller", channel = "<P>_REF", seq = k}, at most once per interval.
    Pure Lua has no sub-second clock, so the interval is measured in 1 ms idle waits of
    lc:handle_timeout(1) plus the plant's own repeats of state k (it repeats every interval).
  * resend_request_t for channel <P>_CMD: re-publish that command if it is remembered.
  * process_status_t heartbeat every 100 ms and on every change of state: role "controller",
    state "running" / "done" / "failed", seq = last answered step, acked_seq = -1,
    counters = resends, duplicates, invalid messages of this process.
  * drive_state_t with end_of_run = true: the run is over. State "done"; keep answering repeats
    and resend requests until the monitor's status says "done" or "failed" (or --linger s,
    default 10), then exit 0.
  * A process_status_t of another role with state "failed", or no progress for --start-timeout
    (30 s, before step 0) / --step-timeout (5 s, after): announce "failed" (3 times, with the
    reason), print one line naming the role and the step, exit 1.
  * Run identity (docs/security.md): every message carries run_id. With --run-id 0 (default)
    the controller joins the run of the first plant heartbeat whose utime is within 5 s of its
    own clock (a replayed log is older), then ignores and counts (status "foreign") every message
    of another run, and stamps its own messages with the run's id.
  * --key FILE (docs/security.md): every message is signed, and every message received must be:
    mac_size = 32 and mac = HMAC-SHA256(key, channel .. "\0" .. E), E = the encoding up to
    mac_size. A message without a valid mac is counted (status "unauthenticated") and dropped.
    Needs luaossl (Debian lua-luaossl). This script does not check the key file's mode (plain
    Lua has no stat): keep it 0600, as the C++ processes require.
  * A message that does not decode as the channel's type is counted (status "invalid") and
    dropped. Handler errors never unwind through LCM's C dispatch: they are kept and re-raised
    after lc:handle_timeout() returns.

Control law (a boundary-layer sliding-mode law with a static friction feed-forward; no model of
the LuGre bristle state and no use of the plant's "truth" fields, so it would run on hardware):
    e  = x_d - x_measured,   e' = v_d - v_measured,   S = e' + lambda*e
    a  = a_d + lambda*e' + eta*sat(S/phi) + k*S + ki*integral(S dt)
    F  = m*a + Fc*tanh(v_d / v_ff)            (Coulomb feed-forward on the *desired* velocity)
    u  = clamp(F / (Ka*Kf), -u_limit, u_limit)
Defaults: m = 102.04 kg, Ka*Kf = 260 N/V, lambda = 50 1/s, eta = 5 m/s^2, k = 10 1/s,
phi = 0.5e-3 m/s, ki = 1e6 1/s^2, Fc = 80 N, v_ff = 1e-3 m/s, u_limit = 10 V.
Why it works: in the boundary layer (|S| < phi) the S loop is
    m*dS/dt = -m*(eta/phi + k)*S - m*ki*integral(S dt) + (friction the feed-forward missed)
with m*(eta/phi + k) = 1.02e6 N per m/s. The missed friction (breakaway Fs = 120 N at the start,
the Stribeck excess Fs - Fc = 40 N at low speed, the bristle transients) is at most ~120 N, so
without the integral |S| <= 1.2e-4 m/s and |e| <= |S|/lambda ~ 2.4 um; the integral (S-loop poles
near -100 and -9900 rad/s for ki = 1e6) removes its slowly varying part. At the 1e-4 s period
(lambda + eta/phi + k)*T = 1.006: the velocity loop is near deadbeat (discrete-time stable < 2).
Measured on scenarios/paper/smc_bl_jerk_limited.yaml (0.1 m S-curve, LuGre friction, ideal
encoder): max |e| = 0.32 um, rms 0.06 um with the defaults; 2.3 um with --ki 0; u stays in
[0, 0.63] V. (feeddrive-controller reaches 2 nm there because it uses the plant's true bristle
state; this law uses only x_measured and v_measured, so it would run on hardware.)
--]]

local lcm = require('lcm')

local script_dir = (arg and arg[0] or ''):match('^(.*)/[^/]*$') or '.'

-- The generated bindings: from LUA_PATH / package.path, else from <repo>/build/lcmtypes/lua.
local ok_types, feeddrive = pcall(require, 'feeddrive')
if not ok_types then
  local dir = script_dir .. '/../../build/lcmtypes/lua'
  package.path = dir .. '/?.lua;' .. dir .. '/?/init.lua;' .. package.path
  ok_types, feeddrive = pcall(require, 'feeddrive')
  if not ok_types then
    io.stderr:write('lua-controller: error: cannot load the feeddrive LCM types (require "feeddrive"); ' ..
                    'add <build>/lcmtypes/lua/?.lua;<build>/lcmtypes/lua/?/init.lua to LUA_PATH\n')
    os.exit(2)
  end
end

-- Options ---------------------------------------------------------------------------------------

local defaults = {
  {'lcm-url', 'udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304', 'LCM URL'},
  {'prefix', 'FD', 'channel prefix: <prefix>_STATE, _CMD, _REF, _STATUS, _RESEND'},
  {'mass', 102.04, 'moving mass m [kg]; default: the run_info_t of the run'},
  {'thrust-gain', 260.0, 'Ka*Kf [N/V]; default: the run_info_t of the run'},
  {'lambda', 50.0, 'sliding surface S = e\' + lambda*e [1/s]'},
  {'eta', 5.0, 'switching gain [m/s^2]'},
  {'k', 10.0, 'proportional gain on S [1/s]'},
  {'phi', 0.5e-3, 'boundary layer of sat(S/phi) [m/s]'},
  {'ki', 1e6, 'integral gain on S [1/s^2] (0: off)'},
  {'coulomb', 80.0, 'Coulomb friction feed-forward Fc [N] (0: off); default: the run_info_t of the run'},
  {'coulomb-velocity', 1e-3, 'feed-forward Fc*tanh(v_d / this) [m/s]'},
  {'u-limit', 10.0, 'the controller saturates u to [-u_limit, u_limit] [V]; default: the run_info_t of the run'},
  {'start-timeout', 30.0, 'seconds to wait for step 0'},
  {'step-timeout', 5.0, 'seconds without progress before failing'},
  {'resend-interval', 0.002, 'ask for a missing reference after this long [s]'},
  {'linger', 10.0, 'after the end: seconds to keep answering until the monitor is done'},
  {'run-id', 0, 'identity of the run (0: join the plant\'s, from its heartbeat)'},
  {'key', '', 'key file: sign and verify every message with HMAC-SHA256 (docs/security.md)'},
}

local function usage(out)
  out:write('usage: lua5.2 examples/lua/controller.lua [options]\n' ..
            'The controller role of a feeddrive lockstep run (docs/external-controllers.md).\n\n')
  for _, d in ipairs(defaults) do
    out:write(string.format('  --%-20s %s (default %s)\n', d[1] .. ' X', d[3], tostring(d[2])))
  end
  out:write('  --quiet                log only warnings and errors\n  --help                 this text\n')
end

local opt = {quiet = false}
for _, d in ipairs(defaults) do opt[d[1]] = d[2] end
local given = {}                -- options set on the command line (run_info_t does not override them)

do
  local i = 1
  while i <= #arg do
    local a = arg[i]
    if a == '--help' or a == '-h' then usage(io.stdout); os.exit(0) end
    if a == '--quiet' or a == '-q' then
      opt.quiet = true
    else
      local name, value = a:match('^%-%-([%w%-]+)=(.*)$')
      if not name then
        name = a:match('^%-%-([%w%-]+)$')
        if name then i = i + 1; value = arg[i] end
      end
      if not name or opt[name] == nil or name == 'quiet' then
        io.stderr:write('lua-controller: error: unknown argument ' .. a .. ' (see --help)\n'); os.exit(2)
      end
      if value == nil then
        io.stderr:write('lua-controller: error: --' .. name .. ' needs a value\n'); os.exit(2)
      end
      if type(opt[name]) == 'number' then
        local n = tonumber(value)
        if n == nil or n ~= n or n == math.huge or n == -math.huge then
          io.stderr:write('lua-controller: error: --' .. name .. ' = ' .. value .. ': not a finite number\n')
          os.exit(2)
        end
        opt[name] = n
      else
        opt[name] = value
      end
      given[name] = true
    end
    i = i + 1
  end
  for _, name in ipairs({'mass', 'thrust-gain', 'lambda', 'phi', 'coulomb-velocity', 'u-limit',
                         'start-timeout', 'step-timeout', 'resend-interval'}) do
    if opt[name] <= 0 then
      io.stderr:write('lua-controller: error: --' .. name .. ' = ' .. opt[name] .. ': must be > 0\n'); os.exit(2)
    end
  end
  if opt['run-id'] < 0 or opt['run-id'] > 2^53 - 1 or opt['run-id'] % 1 ~= 0 then
    io.stderr:write('lua-controller: error: --run-id = ' .. opt['run-id'] .. ': must be an integer in 0..2^53-1\n')
    os.exit(2)
  end
  for _, name in ipairs({'eta', 'k', 'ki', 'coulomb', 'linger'}) do
    if opt[name] < 0 then
      io.stderr:write('lua-controller: error: --' .. name .. ' = ' .. opt[name] .. ': must be >= 0\n'); os.exit(2)
    end
  end
end

local function info(fmt, ...)
  if not opt.quiet then io.stderr:write('[lua-controller] ' .. string.format(fmt, ...) .. '\n') end
end
local function warn(fmt, ...)
  io.stderr:write('[lua-controller] warning: ' .. string.format(fmt, ...) .. '\n')
end

-- Clocks ----------------------------------------------------------------------------------------
-- Lua 5.2 has no sub-second wall clock. /proc/uptime (Linux) ticks every 10 ms, which is plenty
-- for the 100 ms heartbeat and the second-scale timeouts; elsewhere os.time() (1 s) is used.

local function read_uptime()
  local f = io.open('/proc/uptime', 'r')
  if not f then return nil end
  local s = f:read('*l')
  f:close()
  return s and tonumber(s:match('^(%S+)'))
end
local now = read_uptime() and read_uptime or os.time   -- monotonic-ish seconds
local wall0, mono0 = os.time(), now()
local function wall_utime() return math.floor((wall0 + (now() - mono0)) * 1e6) end

-- Protocol state ----------------------------------------------------------------------------------

local P = opt.prefix
local ch = {state = P .. '_STATE', command = P .. '_CMD', reference = P .. '_REF',
            status = P .. '_STATUS', resend = P .. '_RESEND', info = P .. '_INFO'}
local ROLE = 'controller'
local CONTRACT_VERSION = 4       -- the contract of the lcmtypes/ this example's bindings are made from
local RESEND_MS = math.max(1, math.floor(opt['resend-interval'] * 1000 + 0.5))
local KEEP = 65536              -- commands remembered for repeats and resend requests

local lc = lcm.lcm.new(opt['lcm-url'])   -- raises "error lcm create" on a bad URL

local commands = {}             -- seq -> encoded control_command_t
local refs = {}                 -- seq -> reference_t (from the blocks, not yet used)
local peers = {}                -- role -> latest process_status_t
local pending = nil             -- newest unanswered drive_state_t
local pending_age_ms = 0        -- ms the pending state has waited (idle waits + plant repeats)
local last_request_age_ms = 0
local next_seq = 0              -- first step not answered yet
local last_seq = -1             -- last answered step
local ended = false
local run_info = nil            -- the run's run_info_t, once received: no command goes out before it
local state = 'starting'
local counters = {resends = 0, duplicates = 0, invalid = 0, send_errors = 0, foreign = 0, unauthenticated = 0}
local run_id = opt['run-id'] ~= 0 and opt['run-id'] or nil   -- nil: not joined yet

-- Authentication (docs/security.md, "Signing in another language"). luaossl only with --key.
local key = nil
local hmac = nil
if opt.key ~= '' then
  local ok, mod = pcall(require, 'openssl.hmac')
  if not ok then
    io.stderr:write('lua-controller: error: --key needs luaossl (Debian package lua-luaossl)\n'); os.exit(2)
  end
  hmac = mod
  local f = io.open(opt.key, 'rb')
  if not f then io.stderr:write('lua-controller: error: --key ' .. opt.key .. ': cannot open it\n'); os.exit(2) end
  key = f:read('*a')
  f:close()
  if #key < 16 or #key > 4096 then
    io.stderr:write('lua-controller: error: --key ' .. opt.key .. ': ' .. #key .. ' bytes; a key has 16..4096\n')
    os.exit(2)
  end
end
local function mac(channel, body) return hmac.new(key, 'sha256'):final(channel .. '\0' .. body) end

-- The bytes to publish: the message stamped with the run's id, signed with --key. The trailer
-- of an unsigned encoding is mac_size = 0 (two zero bytes); a signed one is 0x00 0x20 and the mac.
local function seal(channel, m)
  m.run_id = run_id or 0
  m.mac_size = 0
  m.mac = {}
  local e = m:encode()
  if not key then return e end
  local body = e:sub(1, #e - 2)
  return body .. '\0\32' .. mac(channel, body)
end

-- True if a received message carries a valid mac (always, without --key).
local function authentic(channel, data)
  if not key then return true end
  if #data < 42 or data:sub(-34, -33) ~= '\0\32' then return false end
  return mac(channel, data:sub(1, -35)) == data:sub(-32)
end
local last_heartbeat = -math.huge
local last_invalid_log = -math.huge
local handler_error = nil       -- first error raised inside an LCM handler
local ctl = {integral = 0.0, last_t = nil, sent = {}, period = nil, saturated_steps = 0, held_steps = 0,
             max_abs_e = 0.0}

-- A run failure is an error value of this shape; anything else is a bug.
local Failure = {}
local function fail(message) error(setmetatable({message = message}, Failure), 0) end

-- lua5.2 turns Ctrl-C (SIGINT) into the error "interrupted!" raised wherever Lua code runs next;
-- a pcall that catches it must pass it on.
local function is_interrupt(err) return type(err) == 'string' and err:match('interrupted!$') ~= nil end

local function publish(channel, encoded)
  local ok, err = pcall(lc.publish, lc, channel, encoded)
  if not ok then
    if is_interrupt(err) then error(err, 0) end
    counters.send_errors = counters.send_errors + 1
  end
  return ok
end

local function send_status(st, message)
  local m = feeddrive.process_status_t:new()
  m.utime = wall_utime()
  m.role = ROLE
  m.state = st
  m.seq = last_seq
  m.acked_seq = -1
  m.contract_version = CONTRACT_VERSION  -- docs/lcm-contract.md, Versions
  m.message = message or ''
  m.resends = counters.resends
  m.duplicates = counters.duplicates
  m.invalid = counters.invalid
  m.foreign = counters.foreign
  m.conflicts = 0               -- this example leaves conflict detection to the plant and the monitor
  m.unauthenticated = counters.unauthenticated
  publish(ch.status, seal(ch.status, m))
end

local function heartbeat(force)
  local t = now()
  if not force and t - last_heartbeat < 0.1 then return end
  last_heartbeat = t
  if run_id then send_status(state) end   -- nothing to say before joining a run
end

local function set_state(s) state = s; heartbeat(true) end

local function announce_failure(message)
  state = 'failed'
  message = message:gsub('[\r\n]+', ' ')
  for _ = 1, 3 do send_status('failed', message) end
end

-- Control law -------------------------------------------------------------------------------------

local function clamp(x, lo, hi) if x < lo then return lo elseif x > hi then return hi else return x end end
local function finite(x) return x == x and x ~= math.huge and x ~= -math.huge end

-- Warns once when the gains do not suit the control period T (learned from the states).
local function check_period(st)
  if ctl.period or st.seq <= 0 or not (st.t > 0) then return end
  local T = st.t / st.seq
  ctl.period = T
  local a = (opt.lambda + opt.eta / opt.phi + opt.k) * T
  if a >= 1.9 then
    warn('(lambda + eta/phi + k)*T = %.3g at T = %g s: the velocity loop is unstable in discrete time ' ..
         '(needs < 2); increase --phi', a, T)
  end
  if opt.ki * T * T > 0.05 then
    warn('ki*T^2 = %.3g at T = %g s: the integral loop is too fast (keep it <= 0.05, e.g. --ki %g)',
         opt.ki * T * T, T, 0.01 / (T * T))
  end
end

local function control(ref, st)
  check_period(st)
  local x, v = st.x_measured, st.v_measured
  local e = ref.position - x
  local ed = ref.velocity - v
  local s = ed + opt.lambda * e
  local a = ref.acceleration + opt.lambda * ed + opt.eta * clamp(s / opt.phi, -1.0, 1.0) + opt.k * s +
            opt.ki * ctl.integral
  local f = opt.mass * a + opt.coulomb * math.tanh(ref.velocity / opt['coulomb-velocity'])
  local u_unsat = f / opt['thrust-gain']
  local u = clamp(u_unsat, -opt['u-limit'], opt['u-limit'])
  if not finite(u) then u = 0.0 end   -- never send NaN/inf (the plant would apply 0 V anyway)
  -- Integral of S, with anti-windup: it only integrates while the loop is closed as designed,
  -- i.e. u is not saturated and the plant applied, over the previous step, the u sent for it
  -- (in real-time mode a late command or the plant's safe state means it did not).
  local dt = ctl.last_t and (st.t - ctl.last_t) or 0.0
  ctl.last_t = st.t
  local p = st.previous
  local applied_as_sent = p.seq < 0 or ctl.sent[p.seq] == p.u
  if u == u_unsat and applied_as_sent and not st.safe_state and finite(s) and dt > 0 then
    ctl.integral = ctl.integral + s * dt
  else
    ctl.held_steps = ctl.held_steps + 1
  end
  ctl.sent[st.seq] = u
  ctl.sent[st.seq - 64] = nil
  if u ~= u_unsat then ctl.saturated_steps = ctl.saturated_steps + 1 end
  if finite(e) and math.abs(e) > ctl.max_abs_e then ctl.max_abs_e = math.abs(e) end
  return u, u_unsat, s
end

local function try_answer()
  if not pending or not run_info then return end
  local ref = refs[pending.seq]
  if not ref then return end
  local st = pending
  pending = nil
  local u, u_unsat, s = control(ref, st)
  local m = feeddrive.control_command_t:new()
  m.seq = st.seq
  m.t = st.t
  m.u = u
  m.u_unsaturated = u_unsat
  m.sliding = s
  m.z_estimate = 0 / 0          -- NaN: this law estimates no bristle state
  local encoded = seal(ch.command, m)    -- signed once; repeats are these bytes
  commands[st.seq] = encoded
  commands[st.seq - KEEP] = nil
  publish(ch.command, encoded)
  next_seq = st.seq + 1
  last_seq = st.seq
  ctl.last_progress = now()
  for k in pairs(refs) do if k <= st.seq then refs[k] = nil end end
end

local function request_resend(channel, seq)
  -- Not joined yet: a request stamped with no run is foreign to every process (and counted so);
  -- the plant repeats its state until we answer.
  if not run_id then return end
  local r = feeddrive.resend_request_t:new()
  r.requester = ROLE
  r.channel = channel
  r.seq = seq
  publish(ch.resend, seal(ch.resend, r))
end
local function request_reference(seq) request_resend(ch.reference, seq) end

-- Subscriptions -----------------------------------------------------------------------------------

local last_drop_log = {}
local function dropped(kind, fmt, ...)
  counters[kind] = counters[kind] + 1
  local t = now()
  if t - (last_drop_log[kind] or -math.huge) > 1 then
    last_drop_log[kind] = t
    warn(fmt, ...)
  end
end

-- any_run: the handler gets messages of every run (the heartbeats, to join one).
local function subscribe(channel, msgtype, handler, any_run)
  lc:subscribe(channel, function(_, data)
    if handler_error ~= nil then return end
    if not authentic(channel, data) then
      dropped('unauthenticated', 'rejected a message on %s without a valid mac (%d so far)', channel,
              counters.unauthenticated + 1)
      return
    end
    local ok, msg = pcall(msgtype.decode, data)
    if not ok and is_interrupt(msg) then handler_error = msg; return end
    if not ok then
      counters.invalid = counters.invalid + 1
      local t = now()
      if t - last_invalid_log > 1 then
        last_invalid_log = t
        warn('ignored a message on %s that is not a %s (%d bytes)', channel, msgtype.name, #data)
      end
      return
    end
    if not any_run then
      if not run_id then return end     -- not joined yet: the plant repeats what matters
      if msg.run_id ~= run_id then
        dropped('foreign', 'ignored a message of another run (run id %.0f) on %s', msg.run_id, channel)
        return
      end
    end
    local ok2, err = pcall(handler, msg)
    if not ok2 then handler_error = err end
  end)
end

subscribe(ch.state, feeddrive.drive_state_t, function(m)
  if m.end_of_run then ended = true; return end
  if m.seq < next_seq then          -- answered already: the command got lost, send it again
    counters.duplicates = counters.duplicates + 1
    local c = commands[m.seq]
    if c and publish(ch.command, c) then counters.resends = counters.resends + 1 end
    return
  end
  if pending and pending.seq == m.seq then
    counters.duplicates = counters.duplicates + 1
    pending_age_ms = pending_age_ms + RESEND_MS   -- the plant repeats a state every interval
    return
  end
  pending = m
  pending_age_ms = 0
  last_request_age_ms = 0
  try_answer()
end)

subscribe(ch.reference, feeddrive.reference_block_t, function(b)
  for i = 1, b.count do
    local m = b.refs[i]
    if m.seq < next_seq or refs[m.seq] then
      counters.duplicates = counters.duplicates + 1
    else
      refs[m.seq] = m
    end
  end
  try_answer()
end)

-- The run describes itself (run_info_t, re-published every second and on request): take the
-- drive's nominal mass, thrust gain, Coulomb friction, the command limit and the period from it,
-- unless given on the command line.
-- The drive's parameters are run_info_t.plant (contract 4): every key of the plant's list by its
-- scenario key, a number in value, an enum's name in name (docs/lcm-contract.md).
local function parameters(m)
  local by_key = {}
  for i = 1, m.plant_count do by_key[m.plant[i].key] = m.plant[i] end
  return function(key)
    local p = by_key[key]
    if p == nil then fail(string.format('run_info_t.plant has no %s (docs/lcm-contract.md)', key)) end
    if p.name ~= '' then return p.name end
    return p.value
  end
end

subscribe(ch.info, feeddrive.run_info_t, function(m)
  if run_info then return end
  if m.contract_version ~= CONTRACT_VERSION then
    fail(string.format('run_info_t of contract version %d, this controller speaks %d (docs/lcm-contract.md, Versions)',
                       m.contract_version, CONTRACT_VERSION))
  end
  run_info = m
  local p = parameters(m)
  local from = {mass = p('mass'), ['thrust-gain'] = p('thrust_gain'),
                coulomb = p('friction.model') == 'none' and 0.0 or p('friction.coulomb_force'),
                ['u-limit'] = math.min(-m.u_min, m.u_max, p('input_limit'))}
  for name, value in pairs(from) do
    if not given[name] and finite(value) and value >= 0 then opt[name] = value end
  end
  info('run %s (%s): T = %g s, %d steps; m %g kg, Ka*Kf %g N/V, Fc %g N, |u| <= %g V (from run_info_t)',
       m.scenario, m.mode, m.control_period, m.steps, opt.mass, opt['thrust-gain'], opt.coulomb, opt['u-limit'])
  ctl.period = nil
  check_period({seq = 1, t = m.control_period})
  try_answer()
end)

subscribe(ch.status, feeddrive.process_status_t, function(m)
  if not run_id then
    -- Join the first plant whose heartbeat is fresh (a replayed log carries old times).
    if m.role ~= 'plant' or math.abs(m.utime - wall_utime()) > 5e6 then return end
    run_id = m.run_id
    info('joined run %.0f (from the plant\'s heartbeat)', run_id)
  end
  if m.run_id ~= run_id then
    dropped('foreign', 'ignored a message of another run (run id %.0f) on %s', m.run_id, ch.status)
    return
  end
  if m.role ~= ROLE then peers[m.role] = m end
end, true)

subscribe(ch.resend, feeddrive.resend_request_t, function(r)
  if r.channel == ch.command then
    local c = commands[r.seq]
    if c and publish(ch.command, c) then counters.resends = counters.resends + 1 end
  end
end)

-- Main loop ---------------------------------------------------------------------------------------

local function check_peers()
  for role, st in pairs(peers) do
    if st.state == 'failed' then
      fail(string.format('%s failed at step %d: %s', role, st.seq, st.message))
    end
  end
end

local function monitor_done()
  local m = peers.monitor
  return m ~= nil and (m.state == 'done' or m.state == 'failed')
end

-- One wait of at most 1 ms; handles at most one message. Returns whether one was handled.
local function poll()
  local got = lc:handle_timeout(1)
  if handler_error ~= nil then
    local e = handler_error
    handler_error = nil
    error(e, 0)
  end
  return got
end

local function run()
  info('%s, prefix %s: lambda %g, eta %g, k %g, phi %g, ki %g, Fc %g N, m %g kg, Ka*Kf %g N/V',
       opt['lcm-url'], P, opt.lambda, opt.eta, opt.k, opt.phi, opt.ki, opt.coulomb, opt.mass, opt['thrust-gain'])
  set_state('running')
  ctl.last_progress = now()
  while not ended do
    local got = poll()
    if not run_info and now() - (ctl.last_info_request or -1) >= 0.1 then  -- joined late: ask for it
      request_resend(ch.info, 0)
      ctl.last_info_request = now()
    end
    if not got and pending then pending_age_ms = pending_age_ms + 1 end
    if pending and pending_age_ms - last_request_age_ms >= RESEND_MS then
      request_reference(pending.seq)
      last_request_age_ms = pending_age_ms
    end
    local t = now()
    local limit = next_seq == 0 and opt['start-timeout'] or opt['step-timeout']
    if t - ctl.last_progress > limit then
      if not run_info then
        fail(string.format('no run_info_t on %s from the monitor within %g s', ch.info, limit))
      end
      if pending then
        fail(string.format('no reference from the trajectory for step %d within %g s', pending.seq, limit))
      end
      fail(string.format('no state from the plant for step %d within %g s', next_seq, limit))
    end
    check_peers()
    heartbeat(false)
  end
  set_state('done')
  info('end of run after %d steps: max |e| seen %.3g m, %d saturated, integral held %d steps, ' ..
       '%d resends, %d duplicates, %d invalid', next_seq, ctl.max_abs_e, ctl.saturated_steps, ctl.held_steps,
       counters.resends, counters.duplicates, counters.invalid)
  local t0 = now()
  while not monitor_done() and now() - t0 < opt.linger do
    poll()
    heartbeat(false)
  end
  if counters.send_errors > 0 then warn('%d publish errors', counters.send_errors) end
end

local ok, err = xpcall(run, function(e)
  if getmetatable(e) == Failure then return e end
  -- Ctrl-C; SIGTERM (e.g. from `timeout`) just ends the process
  if is_interrupt(e) then return setmetatable({message = 'interrupted by SIGINT'}, Failure) end
  return debug.traceback(tostring(e), 2)
end)
if ok then os.exit(0) end
local message = getmetatable(err) == Failure and err.message or ('internal error: ' .. tostring(err))
pcall(announce_failure, message:match('^[^\n]*'))
io.stderr:write('[lua-controller] error: ' .. message .. '\n')
os.exit(1)
