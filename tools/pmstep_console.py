#!/usr/bin/env python3
"""Host console of a pmstep drive: talks the framed command and telemetry protocol of
firmware/console/include/pmstep_console.h over a serial port (the NUCLEO-G431RB's ST-LINK virtual COM
port), a pty, or a TCP socket (QEMU's -serial tcp:...).

Endpoints (--port):
  /dev/ttyACM0, COM5, /dev/pts/7   a serial port or a pty (--baud, default 115200)
  tcp:HOST:PORT                    a TCP socket (e.g. QEMU -serial tcp:127.0.0.1:5555,server=on)
  any pyserial URL                 e.g. socket://HOST:PORT, loop://

Commands (one per run, or several in the interactive mode):
  hello | status | counters | commissioning | start | stop | clear
  speed TARGET_RAD_S [--ramp RAD_S2]     speed target with a ramp rate (default 50 rad/s^2)
  id TARGET_A                            i_d target
  config                                 every configuration value, by id and name
  get NAME|ID      set NAME|ID VALUE     one configuration value (set: motor stopped only)
  telemetry --decimation N [--seconds S] [--csv FILE] [--plot]   stream to CSV, plot live
  move TARGET_RAD [--vmax RAD_S] [--amax RAD_S2] [--jmax RAD_S3]  position move (mechanical rad from
                                         the zero; defaults 5 rad/s, 50 rad/s^2, jerk 0 = a_max varpi_0)
  hold [--amax RAD_S2]                   stop and hold (a_max used only from speed mode)
  position                               theta-hat, theta*, their difference, the flags
  zero                                   the present position becomes 0
  plot FILE.csv                          plot a telemetry CSV afterwards
  interactive                            a prompt for all of the above

Needs pyserial (pinned in tools/requirements.txt); plots need matplotlib (same file).

Every wait is bounded whatever the line does (noise, a flood of sync bytes, a stream of frames, a
line that takes no bytes): a reply comes within its deadline (2 s; SIM_ADVANCE longer) or the request
fails. A failure ends a command with one line on stderr, "pmstep_console: error: ...", and an exit
status by its class (ConsoleError's subclasses; in the interactive mode the shell prints the error
and goes on, except after a line failure, which ends it):
  0  done
  1  the drive answered with an error frame, or the core refused (DeviceError)
  2  usage (argparse)
  3  no reply within the deadline (ReplyTimeout)
  4  a reply too short for its type (MalformedReply)
  5  the line failed or closed: pty closed, serial port unplugged, socket dropped, write stalled
     (LinkError)
  6  the port could not be opened: missing device, refused connection, bad URL (PortOpenError)
"""
import argparse
import cmd
import csv
import math
import shlex
import struct
import sys
import time

try:
    import termios  # a serial port's flush/in_waiting raise termios.error on a line gone away
    LINK_ERRORS = (OSError, termios.error)  # OSError: pyserial's SerialException among them
except ImportError:  # Windows
    LINK_ERRORS = (OSError,)

SYNC = 0xA5
MAX_PAYLOAD = 64

HELLO, START, STOP, CLEAR_FAULT, SPEED_TARGET, ID_TARGET = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
GET_STATUS, GET_CONFIG, SET_CONFIG, GET_COMMISSIONING, TELEMETRY, GET_COUNTERS = 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C
MOVE_TO, HOLD, GET_POSITION, SET_POSITION_ZERO = 0x0D, 0x0E, 0x0F, 0x10
SIM_ADVANCE, SIM_FINISH = 0x40, 0x41
TELEMETRY_FRAME, ERROR_FRAME = 0x90, 0xFF
REQUEST_NAMES = {HELLO: "HELLO", START: "START", STOP: "STOP", CLEAR_FAULT: "CLEAR_FAULT",
                 SPEED_TARGET: "SPEED_TARGET", ID_TARGET: "ID_TARGET", GET_STATUS: "STATUS",
                 GET_CONFIG: "CONFIG", SET_CONFIG: "SET_CONFIG", GET_COMMISSIONING: "COMMISSIONING",
                 TELEMETRY: "TELEMETRY", GET_COUNTERS: "COUNTERS", MOVE_TO: "MOVE_TO", HOLD: "HOLD",
                 GET_POSITION: "POSITION", SET_POSITION_ZERO: "SET_POSITION_ZERO", SIM_ADVANCE: "SIM_ADVANCE",
                 SIM_FINISH: "SIM_FINISH"}

MODES = {0: "IDLE", 1: "S_ALIGN", 2: "C_ALIGN", 3: "RUN", 4: "FAULT", 5: "OFFSET_CAL"}
ERRORS = {1: "unknown command", 2: "bad length", 3: "bad value (NaN, Inf or out of range)",
          4: "unknown configuration value", 5: "read-only value", 6: "refused while the motor runs",
          7: "busy: the previous command has not reached the core yet", 8: "not supported by this image",
          9: "no position control in this image (speed mode only)"}
POSITION_FLAGS = {1: "tracked", 2: "position_mode", 4: "moving"}
STATUS_FIELDS = ["speed_ref_rad_s", "speed_hat_rad_s", "load_hat_Nm", "cos_hat", "sin_hat", "i_a_A", "i_b_A",
                 "bus_voltage_V", "u_a_V", "u_b_V", "i_d_A", "i_q_A"]
TELEMETRY_FIELDS = ["period", "mode", "fault", "speed_ref_rad_s", "speed_hat_rad_s", "load_hat_Nm", "cos_hat",
                    "sin_hat", "i_a_A", "i_b_A", "bus_voltage_V", "u_a_V", "u_b_V", "i_q_A"]
COUNTER_FIELDS = ["rx_bytes", "rx_frames", "rx_garbage_bytes", "rx_bad_length", "rx_crc_errors", "rx_truncated",
                  "rx_error_replies", "commands_applied", "tx_frames", "tx_dropped", "telemetry_frames"]
COMMISSIONING_FIELDS = ["offset_a_A", "offset_b_A", "resistance_Ohm", "phase_a_current_scale", "inductance_H",
                        "torque_constant_Nm_A", "voltage_bias_a_V", "voltage_bias_b_V"]
CONFIG_TYPES = {0: "f32", 1: "u32", 2: "i32", 3: "bool"}


def crc16(data, crc=0xFFFF):
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF)."""
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


def encode(ftype, seq, data=b""):
    """A frame: sync, length, type, seq, data, CRC (little-endian)."""
    payload = bytes([ftype, seq]) + bytes(data)
    if len(payload) > MAX_PAYLOAD:
        raise ValueError("payload too long")
    body = bytes([len(payload)]) + payload
    return bytes([SYNC]) + body + struct.pack("<H", crc16(body))


class Decoder:
    """Frames out of a byte stream (the same rules as the firmware's receiver)."""

    def __init__(self):
        self.buf = bytearray()
        self.bad = 0

    def feed(self, data):
        self.buf += data
        frames = []
        while True:
            start = self.buf.find(bytes([SYNC]))
            if start < 0:
                self.bad += len(self.buf)
                self.buf.clear()
                return frames
            if start > 0:
                self.bad += start
                del self.buf[:start]
            if len(self.buf) < 2:
                return frames
            n = self.buf[1]
            if n < 2 or n > MAX_PAYLOAD:
                self.bad += 1
                del self.buf[:1]
                continue
            if len(self.buf) < n + 4:
                return frames
            body = bytes(self.buf[1:2 + n])
            (crc,) = struct.unpack_from("<H", self.buf, 2 + n)
            if crc16(body) != crc:
                self.bad += 1
                del self.buf[:1]
                continue
            frames.append((body[1], body[2], body[3:]))
            del self.buf[:n + 4]


class ConsoleError(Exception):
    """A request or the line failed; exit_code: the command line's exit status for it (module
    docstring)."""
    exit_code = 1


class DeviceError(ConsoleError):
    """The drive answered with an error frame, or the core refused a command."""
    exit_code = 1


class ReplyTimeout(ConsoleError, TimeoutError):
    """No reply within the deadline (whatever else the line carried meanwhile)."""
    exit_code = 3


class MalformedReply(ConsoleError):
    """A reply of the right type and sequence number, too short for that type."""
    exit_code = 4


class LinkError(ConsoleError):
    """The line failed or closed: a read or write raised (pty closed, port unplugged, socket
    dropped), or a write stalled past the link's write timeout."""
    exit_code = 5


class PortOpenError(LinkError):
    """The port could not be opened (missing device, refused connection, bad URL, no pyserial)."""
    exit_code = 6


# Reply DATA lengths (pmstep_console.h): fixed layouts, or the fixed part before a text. A longer
# reply is accepted (fields a later firmware may append); a shorter one is a MalformedReply.
ACK_BYTES = 6            # status i16, period u32
HELLO_MIN_BYTES = 2      # protocol u8, max payload u8, text
STATUS_BYTES = 60        # period u32, mode, fault, port fault, flags u8, fault step u32, 12 f32
CONFIG_MIN_BYTES = 7     # id, type, flags u8, value f32, name
COMMISSIONING_BYTES = 41  # measured u8, offset samples u32, realignments u32, 8 f32
COUNTERS_BYTES = 44      # 11 u32
POSITION_BYTES = 19      # status i16, period u32, 3 f32, flags u8


def check_reply(ftype, data, n_bytes, text=False):
    """@return @p data, the DATA of the reply to request @p ftype, if it has at least @p n_bytes
    (@p text: a text follows them); else raises MalformedReply."""
    if len(data) < n_bytes:
        name = REQUEST_NAMES.get(ftype, f"0x{ftype:02x}")
        raise MalformedReply(f"malformed {name} reply: {len(data)} bytes, expected {n_bytes}"
                             + (" or more" if text else ""))
    return data


def _reason(e):
    """The cause of a line error in a few words: the innermost OS error's text if there is one
    (pyserial wraps them), else the exception's own."""
    inner = e
    while True:
        if isinstance(inner, OSError) and inner.strerror and not inner.strerror.startswith("could not"):
            return inner.strerror
        nxt = inner.__cause__ or inner.__context__
        if nxt is None:
            break
        inner = nxt
    if len(getattr(e, "args", ())) == 2 and isinstance(e.args[1], str):  # termios.error (errno, text)
        return e.args[1]
    return str(e) or type(e).__name__


def open_endpoint(port, baud=115200, timeout=0.05, write_timeout=2.0):
    """The link to @p port (module docstring); @p timeout bounds a read of one byte, @p
    write_timeout a write (a line that takes no bytes: LinkError, not a hang). Raises
    PortOpenError."""
    try:
        import serial  # pyserial, pinned in tools/requirements.txt
    except ImportError as e:
        raise PortOpenError(f"pyserial is missing ({e}); tools/setup_venv.sh installs tools/requirements.txt") \
            from e
    try:
        if port.startswith("tcp:"):
            host, _, tcp_port = port[4:].rpartition(":")
            if not tcp_port.isdigit():
                raise PortOpenError(f"cannot open port {port}: expected tcp:HOST:PORT or tcp:PORT")
            return serial.serial_for_url(f"socket://{host or '127.0.0.1'}:{tcp_port}", timeout=timeout,
                                         write_timeout=write_timeout)
        return serial.serial_for_url(port, baudrate=baud, timeout=timeout, write_timeout=write_timeout)
    except (ValueError,) + LINK_ERRORS as e:
        raise PortOpenError(f"cannot open port {port}: {_reason(e)}") from e


class Console:
    """One drive: requests with replies matched by sequence number; telemetry frames go to
    the on_telemetry callback (and are kept in self.telemetry)."""

    def __init__(self, link, reply_timeout=2.0):
        self.link = link
        self.decoder = Decoder()
        self.seq = 0
        self.reply_timeout = reply_timeout
        self.telemetry = []
        self.on_telemetry = None
        self.pending = []

    # ---- transport ----
    def _dispatch(self, frame):
        ftype, seq, data = frame
        if ftype == TELEMETRY_FRAME and len(data) == 50:
            values = struct.unpack("<IBB11f", data)
            row = dict(zip(TELEMETRY_FIELDS, values))
            self.telemetry.append(row)
            if self.on_telemetry:
                self.on_telemetry(row)
            return None
        return frame

    def _line_error(self, doing, e):
        port = getattr(self.link, "port", None)
        serial = sys.modules.get("serial")
        if serial is not None and isinstance(e, serial.SerialTimeoutException):
            reason = f"the line took no bytes for {self.link.write_timeout:g} s"
        else:
            reason = _reason(e)
        return LinkError(f"{port + ': ' if port else ''}the line failed or closed while {doing}: {reason}")

    def _read(self):
        """What has arrived, or one byte within the link's timeout (b"" if none): a peer that closes
        right after its last frame (an image that exits) loses nothing. Raises LinkError."""
        try:
            return self.link.read(max(1, self.link.in_waiting))
        except LINK_ERRORS as e:
            raise self._line_error("reading", e) from e

    def pump(self, wait=0.0):
        """Reads what arrives for @p wait s (at least one read), dispatches telemetry and keeps the
        other frames in self.pending. Returns at the deadline (plus at most one read) whatever the
        line does: noise, sync bytes or frames that keep coming do not hold it. Raises LinkError."""
        deadline = time.monotonic() + wait
        while True:
            data = self._read()
            if data:
                for frame in self.decoder.feed(data):
                    kept = self._dispatch(frame)
                    if kept is not None:
                        self.pending.append(kept)
            if time.monotonic() >= deadline:
                return

    def send(self, ftype, data=b""):
        """Sends a request without waiting; @return its sequence number (for wait_reply). A write
        that the line does not take within the link's write timeout raises LinkError. (No flush:
        the kernel has the bytes once write returns, and tcdrain would wait on the line unbounded.)"""
        self.seq = (self.seq + 1) & 0xFF
        try:
            self.link.write(encode(ftype, self.seq, data))
        except LINK_ERRORS as e:
            raise self._line_error("writing", e) from e
        return self.seq

    def request(self, ftype, data=b"", timeout=None):
        return self.wait_reply(ftype, self.send(ftype, data), timeout)

    def _take_reply(self, ftype, seq):
        """The DATA of the reply to (@p ftype, @p seq) if it is pending (removed), else None;
        raises DeviceError for an error reply."""
        for i, (rtype, rseq, rdata) in enumerate(self.pending):
            if rseq == seq and rtype in (ftype | 0x80, ERROR_FRAME):
                del self.pending[i]
                if rtype == ERROR_FRAME:
                    code = rdata[1] if len(rdata) > 1 else 0
                    raise DeviceError(f"request 0x{ftype:02x}: {ERRORS.get(code, f'error {code}')}")
                return rdata
        return None

    def wait_reply(self, ftype, seq, timeout=None):
        """The DATA of the reply to request (@p ftype, @p seq) within @p timeout s (default
        self.reply_timeout), else ReplyTimeout, whatever the line carries meanwhile; DeviceError
        for an error reply, LinkError if the line fails first."""
        timeout_s = self.reply_timeout if timeout is None else timeout
        deadline = time.monotonic() + timeout_s
        while True:
            rdata = self._take_reply(ftype, seq)
            if rdata is not None:
                return rdata
            now = time.monotonic()
            if now > deadline:
                raise ReplyTimeout(f"no reply to request 0x{ftype:02x} (seq {seq}) within {timeout_s:g} s")
            try:
                self.pump(min(0.01, deadline - now))
            except LinkError:
                rdata = self._take_reply(ftype, seq)  # it came with the line's last bytes
                if rdata is not None:
                    return rdata
                raise

    def _ack(self, ftype, data=b"", timeout=None):
        rdata = check_reply(ftype, self.request(ftype, data, timeout), ACK_BYTES)
        status, period = struct.unpack_from("<hI", rdata)
        if status != 0:
            raise DeviceError(f"the core refused request 0x{ftype:02x}: status {status}")
        return period

    # ---- commands ----
    def hello(self):
        d = check_reply(HELLO, self.request(HELLO), HELLO_MIN_BYTES, text=True)
        return {"protocol": d[0], "max_payload": d[1], "identity": d[2:].decode("ascii", "replace")}

    def start(self):
        return self._ack(START)

    def stop(self):
        return self._ack(STOP)

    def clear_fault(self):
        return self._ack(CLEAR_FAULT)

    def speed(self, target_rad_s, ramp_rad_s2=50.0):
        return self._ack(SPEED_TARGET, struct.pack("<ff", target_rad_s, ramp_rad_s2))

    def id_target(self, target_a):
        return self._ack(ID_TARGET, struct.pack("<f", target_a))

    def status(self):
        d = check_reply(GET_STATUS, self.request(GET_STATUS), STATUS_BYTES)
        period, mode, fault, port_fault, flags, fault_step = struct.unpack_from("<IBBBBI", d)
        values = struct.unpack_from("<12f", d, 12)
        s = {"period": period, "mode": MODES.get(mode, str(mode)), "fault": fault, "port_fault": port_fault,
             "bridge_enable": bool(flags & 1), "voltage_limited": bool(flags & 2), "fault_step": fault_step}
        s.update(zip(STATUS_FIELDS, values))
        return s

    def counters(self):
        d = check_reply(GET_COUNTERS, self.request(GET_COUNTERS), COUNTERS_BYTES)
        return dict(zip(COUNTER_FIELDS, struct.unpack_from("<11I", d)))

    def commissioning(self):
        d = check_reply(GET_COMMISSIONING, self.request(GET_COMMISSIONING), COMMISSIONING_BYTES)
        measured, samples, realignments = struct.unpack_from("<BII", d)
        c = {"measured": bool(measured), "offset_samples": samples, "realignments": realignments}
        c.update(zip(COMMISSIONING_FIELDS, struct.unpack_from("<8f", d, 9)))
        return c

    @staticmethod
    def _key(key):
        if isinstance(key, int) or (isinstance(key, str) and key.isdigit()):
            return bytes([int(key)])
        return b"\xff", key.encode("ascii")

    def get_config(self, key):
        k = self._key(key)
        d = check_reply(GET_CONFIG, self.request(GET_CONFIG, k if isinstance(k, bytes) else k[0] + k[1]),
                        CONFIG_MIN_BYTES, text=True)
        cid, ctype, flags, value = struct.unpack_from("<BBBf", d)
        try:
            name = d[7:].decode("ascii")
        except UnicodeDecodeError:
            raise MalformedReply(f"malformed CONFIG reply: the name of value {cid} is not ASCII") from None
        return {"id": cid, "name": name, "type": CONFIG_TYPES.get(ctype, "?"),
                "read_only": bool(flags & 1), "value": value}

    def set_config(self, key, value):
        k = self._key(key)
        v = struct.pack("<f", float(value))
        return self._ack(SET_CONFIG, k + v if isinstance(k, bytes) else k[0] + v + k[1])

    def list_config(self):
        out = []
        for cid in range(255):
            try:
                out.append(self.get_config(cid))
            except DeviceError:
                break
        return out

    def set_telemetry(self, decimation):
        return self._ack(TELEMETRY, struct.pack("<I", decimation))

    def move_to(self, target_rad, v_max_rad_s=5.0, a_max_rad_s2=50.0, j_max_rad_s3=0.0):
        return self._ack(MOVE_TO, struct.pack("<ffff", target_rad, v_max_rad_s, a_max_rad_s2, j_max_rad_s3))

    def hold(self, a_max_rad_s2=None):
        return self._ack(HOLD, b"" if a_max_rad_s2 is None else struct.pack("<f", a_max_rad_s2))

    def set_position_zero(self):
        return self._ack(SET_POSITION_ZERO)

    def position(self):
        """The present period's estimate and theta* (mechanical rad); status != 0 (e.g. -2: not
        tracked, not in RUN) comes back in the dict with zero positions."""
        d = check_reply(GET_POSITION, self.request(GET_POSITION), POSITION_BYTES)
        status, period, pos, ref, err, flags = struct.unpack_from("<hIfffB", d)
        p = {"status": status, "period": period, "position_rad": pos, "position_ref_rad": ref,
             "position_error_rad": err}
        p.update({name: bool(flags & bit) for bit, name in POSITION_FLAGS.items()})
        return p

    def sim_advance(self, periods, timeout=120.0):
        return self._ack(SIM_ADVANCE, struct.pack("<I", periods), timeout=timeout)

    def sim_finish(self):
        return self._ack(SIM_FINISH)


# ---- telemetry to CSV, plots ----
def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=TELEMETRY_FIELDS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})


def read_csv(path):
    with open(path, newline="") as f:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


PLOTS = [("speed_hat_rad_s", "speed_ref_rad_s", "rad/s"), ("load_hat_Nm", None, "Nm"),
         ("i_a_A", "i_b_A", "A"), ("cos_hat", "sin_hat", "")]


def plot_rows(rows, period_s=50e-6, path=None):
    import matplotlib
    if path:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(PLOTS), 1, sharex=True, figsize=(8, 8))
    t = [r["period"] * period_s for r in rows]
    for ax, (a, b, unit) in zip(axes, PLOTS):
        ax.plot(t, [r[a] for r in rows], label=a)
        if b:
            ax.plot(t, [r[b] for r in rows], label=b)
        ax.set_ylabel(unit)
        ax.legend(loc="upper left", fontsize="small")
    axes[-1].set_xlabel("t (s)")
    if path:
        fig.savefig(path)
    else:
        plt.show()


def stream(con, decimation, seconds, csv_path=None, live_plot=False):
    rows = []
    con.telemetry = rows
    con.set_telemetry(decimation)
    end = time.monotonic() + seconds
    if live_plot:
        import matplotlib.pyplot as plt
        plt.ion()
        fig, ax = plt.subplots()
        (line_hat,) = ax.plot([], [], label="speed_hat_rad_s")
        (line_ref,) = ax.plot([], [], label="speed_ref_rad_s")
        ax.legend()
        while time.monotonic() < end:
            con.pump(0.1)
            if rows:
                x = [r["period"] for r in rows]
                line_hat.set_data(x, [r["speed_hat_rad_s"] for r in rows])
                line_ref.set_data(x, [r["speed_ref_rad_s"] for r in rows])
                ax.relim()
                ax.autoscale_view()
                plt.pause(0.01)
    else:
        while time.monotonic() < end:
            con.pump(0.1)
    con.set_telemetry(0)
    con.pump(0.1)
    if csv_path:
        write_csv(csv_path, rows)
    return rows


# ---- command line ----
def print_dict(d):
    for k, v in d.items():
        print(f"  {k:26s} {v:.6g}" if isinstance(v, float) else f"  {k:26s} {v}")


def run_command(con, argv):
    """One command; returns False for an unknown one."""
    p = argparse.ArgumentParser(prog="pmstep-console command", add_help=False)
    p.add_argument("what")
    p.add_argument("args", nargs="*")
    p.add_argument("--ramp", type=float, default=50.0)
    p.add_argument("--decimation", type=int, default=200)
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--csv")
    p.add_argument("--plot", action="store_true")
    p.add_argument("--period", type=float, default=50e-6)
    p.add_argument("--vmax", type=float, default=5.0)
    p.add_argument("--amax", type=float, default=None)
    p.add_argument("--jmax", type=float, default=0.0)
    a = p.parse_args(argv)
    w = a.what
    if w == "hello":
        print_dict(con.hello())
    elif w == "status":
        print_dict(con.status())
    elif w == "counters":
        print_dict(con.counters())
    elif w == "commissioning":
        print_dict(con.commissioning())
    elif w in ("start", "stop", "clear"):
        period = {"start": con.start, "stop": con.stop, "clear": con.clear_fault}[w]()
        print(f"{w}: done from period {period}")
    elif w == "speed":
        print(f"speed target {a.args[0]} rad/s at {a.ramp} rad/s^2: from period {con.speed(float(a.args[0]), a.ramp)}")
    elif w == "id":
        print(f"i_d target {a.args[0]} A: from period {con.id_target(float(a.args[0]))}")
    elif w == "config":
        for c in con.list_config():
            ro = " (read-only)" if c["read_only"] else ""
            print(f"  {c['id']:3d} {c['name']:34s} {c['value']:.7g} {c['type']}{ro}")
    elif w == "get":
        c = con.get_config(a.args[0])
        print(f"  {c['id']} {c['name']} = {c['value']:.7g} ({c['type']})")
    elif w == "set":
        print(f"set {a.args[0]} = {a.args[1]}: done (core re-initialised) at period {con.set_config(a.args[0], a.args[1])}")
    elif w == "move":
        amax = 50.0 if a.amax is None else a.amax
        period = con.move_to(float(a.args[0]), a.vmax, amax, a.jmax)
        print(f"move to {a.args[0]} rad at {a.vmax} rad/s, {amax} rad/s^2: from period {period}")
    elif w == "hold":
        print(f"hold: from period {con.hold(a.amax)}")
    elif w == "zero":
        print(f"zero: the position is 0 from period {con.set_position_zero()}")
    elif w == "position":
        print_dict(con.position())
    elif w == "telemetry":
        rows = stream(con, a.decimation, a.seconds, a.csv, a.plot)
        print(f"{len(rows)} telemetry frames" + (f" written to {a.csv}" if a.csv else ""))
    else:
        return False
    return True


class Shell(cmd.Cmd):
    intro = "pmstep console: hello, status, start, stop, clear, speed T [--ramp R], id A, config, get K, " \
            "set K V, commissioning, counters, telemetry [--decimation N --seconds S --csv F --plot], " \
            "move X [--vmax V --amax A --jmax J], hold [--amax A], position, zero, quit"
    prompt = "pmstep> "

    def __init__(self, con):
        super().__init__()
        self.con = con

    def default(self, line):
        """One command; its failure is one "error: ..." line and the shell goes on, except a line
        failure (LinkError), which ends the shell (main reports it)."""
        try:
            if not run_command(self.con, shlex.split(line)):
                print(f"unknown command: {line}")
        except LinkError:
            raise
        except (ConsoleError, ValueError, IndexError, SystemExit) as e:
            print(f"error: {e}")

    def do_quit(self, _):
        return True

    do_EOF = do_quit


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--port", help="serial device, pty, tcp:HOST:PORT or a pyserial URL")
    ap.add_argument("--baud", type=int, default=115200)
    ap.add_argument("command", nargs=argparse.REMAINDER, help="see below")
    a = ap.parse_args(argv)
    if a.command and a.command[0] == "plot":
        plot_rows(read_csv(a.command[1]), path=a.command[2] if len(a.command) > 2 else None)
        return 0
    if not a.port:
        ap.error("--port is required")
    link = None
    try:
        link = open_endpoint(a.port, a.baud)
        con = Console(link)
        if not a.command or a.command[0] == "interactive":
            Shell(con).cmdloop()
            return 0
        if not run_command(con, a.command):
            ap.error(f"unknown command {a.command[0]}")
    except ConsoleError as e:  # one line, the exit status of its class (module docstring)
        print(f"pmstep_console: error: {e}", file=sys.stderr)
        return e.exit_code
    finally:
        if link is not None:
            try:
                link.close()
            except LINK_ERRORS:
                pass  # the line is gone already: reported above
    return 0


if __name__ == "__main__":
    sys.exit(main())
