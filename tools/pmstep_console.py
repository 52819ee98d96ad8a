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
  home +|- --travel RAD [--speed RAD_S] [--stall-current A] [--timeout S] [--advance N]
                                         homing without a switch: toward a hard stop (at most TRAVEL
                                         rad), found by the following error or the stall current, the
                                         zero put there, a full step back; speed and stall current
                                         the designer's unless given; progress printed
  plot FILE.csv                          plot a telemetry CSV afterwards
  interactive                            a prompt for all of the above

The stored configuration (a drive whose HELLO says it has a store; motor stopped):
  setup (--motor MOTOR.ini | --motor-db FILE --name NAME) [--robust] [--set SECTION.KEY=VALUE]...
        [--bus-voltage V] [--tune PMSTEP_TUNE]
                                         design gains for the motor with pmstep-tune for the board's
                                         period, delay and sensing ranges, write them as a record,
                                         apply, read back, compare, save
  backup FILE.json                       the board's record: identity, format, ids, every value by
                                         name, the measured values, the raw record (hex)
  restore FILE.json [--save]             a backup's values by name onto the board's record: write,
                                         apply, read back, compare (--save: and save)
  save                                   the configuration in force to flash
  erase                                  both flash slots erased, the board's defaults in force
                                         (no motor configured)
  defaults                               the board's defaults in force, the flash untouched
  store                                  the store's state: configured, boot outcome, slot, sequence
  calibrate --current RATED_A [--pole-pairs P] [--paper] [--detent-fraction D] [--timeout S] [--advance N]
                                         the drive measures R, L, k_M, identifies J, F, designs its gains
                                         and saves them (p 50 by default: a 1.8 deg stepper; detent 0.05 of
                                         the holding torque, 0 for a motor without one); progress printed;
                                         --advance N: a simulation image's N periods per poll
pmstep-tune: --tune PATH, else $PMSTEP_TUNE, else build/host-release/sil/pmstep-tune of this tree.

Needs pyserial (pinned in tools/requirements.txt); plots need matplotlib (same file).

Every wait is bounded whatever the line does (noise, a flood of sync bytes, a stream of frames, a
line that takes no bytes): a reply comes within its deadline (2 s; SIM_ADVANCE longer) or the request
fails. A failure ends a command with one line on stderr, "pmstep_console: error: ...", and an exit
status by its class (ConsoleError's subclasses; in the interactive mode the shell prints the error
and goes on, except after a line failure, which ends it):
  0  done
  1  refused: the drive answered with an error frame, or the core or the store refused (DeviceError);
     a design, backup or read-back that does not fit the board (ConfigurationRefused)
  2  usage: a bad argument (argparse), a missing pmstep-tune or file, a file that is no backup
     (UsageError)
  3  no reply within the deadline (ReplyTimeout)
  4  a reply too short for its type (MalformedReply)
  5  the line failed or closed: pty closed, serial port unplugged, socket dropped, write stalled
     (LinkError)
  6  the port could not be opened: missing device, refused connection, bad URL (PortOpenError)
"""

import argparse
import cmd
import configparser
import csv
import importlib.util
import json
import math
import os
import shlex
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

try:
    import termios  # a serial port's flush/in_waiting raise termios.error on a line gone away

    LINK_ERRORS = (OSError, termios.error)  # OSError: pyserial's SerialException among them
except ImportError:  # Windows
    LINK_ERRORS = (OSError,)

ROOT = Path(__file__).resolve().parent.parent  # the source tree this tool is part of

SYNC = 0xA5
MAX_PAYLOAD = 64
PROTOCOL_VERSION = 2  # HELLO's layout this tool reads; a version 1 drive has no store

HELLO, START, STOP, CLEAR_FAULT, SPEED_TARGET, ID_TARGET = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
GET_STATUS, GET_CONFIG, SET_CONFIG, GET_COMMISSIONING, TELEMETRY, GET_COUNTERS = 0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C
MOVE_TO, HOLD, GET_POSITION, SET_POSITION_ZERO = 0x0D, 0x0E, 0x0F, 0x10
CONFIG_READ, CONFIG_WRITE, CONFIG_APPLY, CONFIG_SAVE = 0x11, 0x12, 0x13, 0x14
CONFIG_ERASE, CONFIG_DEFAULTS, CONFIG_STATUS = 0x15, 0x16, 0x17
CALIBRATE, CALIBRATE_STATUS = 0x18, 0x19
HOME, HOME_STATUS = 0x1A, 0x1B
SIM_ADVANCE, SIM_FINISH, SIM_STEPS, SIM_FOLLOW_STEPS, SIM_STEPDIR = 0x40, 0x41, 0x42, 0x43, 0x44
TELEMETRY_FRAME, ERROR_FRAME = 0x90, 0xFF
REQUEST_NAMES = {
    HELLO: "HELLO",
    START: "START",
    STOP: "STOP",
    CLEAR_FAULT: "CLEAR_FAULT",
    SPEED_TARGET: "SPEED_TARGET",
    ID_TARGET: "ID_TARGET",
    GET_STATUS: "STATUS",
    GET_CONFIG: "CONFIG",
    SET_CONFIG: "SET_CONFIG",
    GET_COMMISSIONING: "COMMISSIONING",
    TELEMETRY: "TELEMETRY",
    GET_COUNTERS: "COUNTERS",
    MOVE_TO: "MOVE_TO",
    HOLD: "HOLD",
    GET_POSITION: "POSITION",
    SET_POSITION_ZERO: "SET_POSITION_ZERO",
    CONFIG_READ: "CONFIG_READ",
    CONFIG_WRITE: "CONFIG_WRITE",
    CONFIG_APPLY: "CONFIG_APPLY",
    CONFIG_SAVE: "CONFIG_SAVE",
    CONFIG_ERASE: "CONFIG_ERASE",
    CONFIG_DEFAULTS: "CONFIG_DEFAULTS",
    CONFIG_STATUS: "CONFIG_STATUS",
    CALIBRATE: "CALIBRATE",
    CALIBRATE_STATUS: "CALIBRATE_STATUS",
    HOME: "HOME",
    HOME_STATUS: "HOME_STATUS",
    SIM_ADVANCE: "SIM_ADVANCE",
    SIM_FINISH: "SIM_FINISH",
    SIM_STEPS: "SIM_STEPS",
    SIM_FOLLOW_STEPS: "SIM_FOLLOW_STEPS",
    SIM_STEPDIR: "SIM_STEPDIR",
}

MODES = {0: "IDLE", 1: "S_ALIGN", 2: "C_ALIGN", 3: "RUN", 4: "FAULT", 5: "OFFSET_CAL"}
ERRORS = {
    1: "unknown command",
    2: "bad length",
    3: "bad value (NaN, Inf or out of range)",
    4: "unknown configuration value",
    5: "read-only value",
    6: "refused while the motor runs",
    7: "busy: the previous command has not reached the core yet",
    8: "not supported by this image",
    9: "no position control in this image (speed mode only)",
    10: "no motor configured",
    11: "no stored configuration in this image",
    12: "no self-commissioning (CALIBRATE) in this image",
}
ERR_NOT_CONFIGURED = 10
HELLO_STORE, HELLO_CONFIGURED = 1, 2  # HELLO flags
POSITION_FLAGS = {1: "tracked", 2: "position_mode", 4: "moving"}
SIM_STEPDIR_FLAGS = {1: "following", 2: "moving", 4: "diag"}
SIM_STEPS_MAX = 60  # periods of STEP edges one SIM_STEPS carries (PMSTEP_CONSOLE_SIM_STEPS_MAX)
STATUS_FIELDS = [
    "speed_ref_rad_s",
    "speed_hat_rad_s",
    "load_hat_Nm",
    "cos_hat",
    "sin_hat",
    "i_a_A",
    "i_b_A",
    "bus_voltage_V",
    "u_a_V",
    "u_b_V",
    "i_d_A",
    "i_q_A",
]
TELEMETRY_FIELDS = [
    "period",
    "mode",
    "fault",
    "speed_ref_rad_s",
    "speed_hat_rad_s",
    "load_hat_Nm",
    "cos_hat",
    "sin_hat",
    "i_a_A",
    "i_b_A",
    "bus_voltage_V",
    "u_a_V",
    "u_b_V",
    "i_q_A",
]
COUNTER_FIELDS = [
    "rx_bytes",
    "rx_frames",
    "rx_garbage_bytes",
    "rx_bad_length",
    "rx_crc_errors",
    "rx_truncated",
    "rx_error_replies",
    "commands_applied",
    "tx_frames",
    "tx_dropped",
    "telemetry_frames",
]
COMMISSIONING_FIELDS = [
    "offset_a_A",
    "offset_b_A",
    "resistance_Ohm",
    "phase_a_current_scale",
    "inductance_H",
    "torque_constant_Nm_A",
    "voltage_bias_a_V",
    "voltage_bias_b_V",
]
CONFIG_TYPES = {0: "f32", 1: "u32", 2: "i32", 3: "bool"}

# The record of the stored configuration (firmware/console/include/pmstep_store.h): a header, the
# configuration table's values (f32 each, in id order), what they were measured with, a CRC-32.
RECORD_MAGIC = 0x52534D50  # "PMSR" in memory order (little-endian)
RECORD_FORMAT = 1  # the record format this tool reads and writes
RECORD_HEADER = struct.Struct("<IHHIIIHHII")  # magic, format, header bytes, board id, layout id,
#                                                sequence, value count, measured count, record bytes, reserved
MEASURED_FIELDS = [
    "flags",
    "offset_a_A",
    "offset_b_A",
    "resistance_Ohm",
    "inductance_H",
    "torque_constant_Nm_A",
    "inertia_kgm2",
    "friction_Nms_rad",
]  # flags u32, then f32 each
CONFIG_STATUS_BYTES = 23  # configured u8, boot, validation, last i16, slot i8, sequence u32, record bytes u16,
#                            format u8, layout id u32, board id u32
CONFIG_READ_MIN_BYTES = 4  # offset u16, total u16, then the bytes
CALIBRATE_STATUS_BYTES = 28  # stage u8, status i16, fault u8, runs u8, identification u8, save status i16, 5 f32
CALIBRATE_STAGES = {0: "idle", 1: "measuring", 2: "identifying", 3: "done", 4: "failed"}
IDENTIFICATION = {0: "off", 1: "running", 2: "done", 3: "friction negative", 4: "poor excitation", 5: "implausible"}
CALIBRATE_PAPER_MODE = 1  # CALIBRATE flags

# pmstep_store_status_t (pmstep_store.h): C name, a short name, what it means. A test checks this
# table against the header.
STORE_CODES = {
    0: ("PMSTEP_STORE_OK", "ok", "done"),
    -140: ("PMSTEP_STORE_EMPTY", "empty", "no record in either slot: never saved, or erased"),
    -141: ("PMSTEP_STORE_ERR_CRC", "bad CRC", "the record's CRC does not match its bytes"),
    -142: ("PMSTEP_STORE_ERR_FORMAT", "another format", "a record of another firmware"),
    -143: ("PMSTEP_STORE_ERR_LAYOUT", "another layout", "a record of another firmware's configuration table"),
    -144: (
        "PMSTEP_STORE_ERR_BOARD",
        "another board",
        "made for another board: its id or its read-only values (period, delay, sensing) differ",
    ),
    -145: ("PMSTEP_STORE_ERR_LENGTH", "bad length", "the record's length does not match its counts or the bytes"),
    -146: ("PMSTEP_STORE_ERR_INVALID", "invalid", "a value the configuration cannot take, or one the core refuses"),
    -147: ("PMSTEP_STORE_ERR_FLASH", "flash error", "the flash reported an error; the previous record stays in force"),
    -148: ("PMSTEP_STORE_ERR_VERIFY", "verify failed", "the slot read back differs from what was programmed"),
    -149: ("PMSTEP_STORE_ERR_BRIDGE_ON", "bridge on", "a flash write asked for while the bridge may switch"),
    -150: ("PMSTEP_STORE_ERR_SLOT_SIZE", "slot too small", "the port's flash slots are smaller than a record"),
    -151: ("PMSTEP_STORE_ERR_NULL", "no flash", "a NULL argument, or no flash given"),
}


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
            body = bytes(self.buf[1 : 2 + n])
            (crc,) = struct.unpack_from("<H", self.buf, 2 + n)
            if crc16(body) != crc:
                self.bad += 1
                del self.buf[:1]
                continue
            frames.append((body[1], body[2], body[3:]))
            del self.buf[: n + 4]


class ConsoleError(Exception):
    """A request or the line failed; exit_code: the command line's exit status for it (module
    docstring)."""

    exit_code = 1


class DeviceError(ConsoleError):
    """The drive answered with an error frame (code: its error code, request: the request's type), or
    the core or the store refused a command (status: the ACK's status)."""

    exit_code = 1

    def __init__(self, message, code=None, request=None, status=None):
        super().__init__(message)
        self.code = code
        self.request = request
        self.status = status


class ConfigurationRefused(DeviceError):
    """The tool refuses a design or a backup that does not fit the board, or a record read back that
    differs from the one written."""

    exit_code = 1


class UsageError(ConsoleError):
    """A bad argument: a missing pmstep-tune or file, a file that is no backup, conflicting options."""

    exit_code = 2


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
ACK_BYTES = 6  # status i16, period u32
HELLO_MIN_BYTES = 2  # protocol u8, max payload u8, text (protocol 1)
HELLO_V2_MIN_BYTES = 4  # protocol u8, max payload u8, record format u8, flags u8, text (protocol 2)
STATUS_BYTES = 60  # period u32, mode, fault, port fault, flags u8, fault step u32, 12 f32
CONFIG_MIN_BYTES = 7  # id, type, flags u8, value f32, name
COMMISSIONING_BYTES = 41  # measured u8, offset samples u32, realignments u32, 8 f32
COUNTERS_BYTES = 44  # 11 u32
POSITION_BYTES = 19  # status i16, period u32, 3 f32, flags u8
HOME_STATUS_BYTES = 16  # status i16, period u32, state u8, found by u8, stop f32, position f32
HOMING_STATES = {0: "idle", 1: "seeking", 2: "backing off", 3: "done", 4: "not found", 5: "aborted"}
SIM_STEPDIR_BYTES = 23  # period u32, steps i32, edges i32, counter u16, flags u8, 2 f32


def check_reply(ftype, data, n_bytes, text=False):
    """@return @p data, the DATA of the reply to request @p ftype, if it has at least @p n_bytes
    (@p text: a text follows them); else raises MalformedReply."""
    if len(data) < n_bytes:
        name = REQUEST_NAMES.get(ftype, f"0x{ftype:02x}")
        raise MalformedReply(
            f"malformed {name} reply: {len(data)} bytes, expected {n_bytes}" + (" or more" if text else "")
        )
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
        raise PortOpenError(f"pyserial is missing ({e}); tools/setup_venv.sh installs tools/requirements.txt") from e
    try:
        if port.startswith("tcp:"):
            host, _, tcp_port = port[4:].rpartition(":")
            if not tcp_port.isdigit():
                raise PortOpenError(f"cannot open port {port}: expected tcp:HOST:PORT or tcp:PORT")
            return serial.serial_for_url(
                f"socket://{host or '127.0.0.1'}:{tcp_port}", timeout=timeout, write_timeout=write_timeout
            )
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

    def pump(self, wait=0.0, until_frame=False):
        """Reads what arrives for @p wait s (at least one read), dispatches telemetry and keeps the
        other frames in self.pending; @p until_frame: returns as soon as one is kept (a reply's wait
        ends when it comes, not a read's timeout later). Returns at the deadline (plus at most one
        read) whatever the line does: noise, sync bytes or frames that keep coming do not hold it.
        Raises LinkError."""
        deadline = time.monotonic() + wait
        while True:
            data = self._read()
            kept_one = False
            if data:
                for frame in self.decoder.feed(data):
                    kept = self._dispatch(frame)
                    if kept is not None:
                        self.pending.append(kept)
                        kept_one = True
            if time.monotonic() >= deadline or (until_frame and kept_one):
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
                    raise DeviceError(
                        f"request 0x{ftype:02x}: {ERRORS.get(code, f'error {code}')}", code=code, request=ftype
                    )
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
                self.pump(min(0.01, deadline - now), until_frame=True)
            except LinkError:
                rdata = self._take_reply(ftype, seq)  # it came with the line's last bytes
                if rdata is not None:
                    return rdata
                raise

    def _ack_status(self, ftype, data=b"", timeout=None):
        """(status, period) of an ACK, whatever the status."""
        rdata = check_reply(ftype, self.request(ftype, data, timeout), ACK_BYTES)
        return struct.unpack_from("<hI", rdata)

    def _ack(self, ftype, data=b"", timeout=None):
        status, period = self._ack_status(ftype, data, timeout)
        if status != 0:
            raise DeviceError(
                f"the core refused request 0x{ftype:02x}: {describe_code(status)}", status=status, request=ftype
            )
        return period

    # ---- commands ----
    def hello(self):
        """Protocol version, largest payload, identity text; from protocol 2 also the record format
        (0: no store), whether a store is attached and whether a motor is configured."""
        d = check_reply(HELLO, self.request(HELLO), HELLO_MIN_BYTES, text=True)
        if d[0] < 2:
            return {"protocol": d[0], "max_payload": d[1], "identity": d[2:].decode("ascii", "replace")}
        d = check_reply(HELLO, d, HELLO_V2_MIN_BYTES, text=True)
        return {
            "protocol": d[0],
            "max_payload": d[1],
            "record_format": d[2],
            "store": bool(d[3] & HELLO_STORE),
            "configured": bool(d[3] & HELLO_CONFIGURED),
            "identity": d[4:].decode("ascii", "replace"),
        }

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
        s = {
            "period": period,
            "mode": MODES.get(mode, str(mode)),
            "fault": fault,
            "port_fault": port_fault,
            "bridge_enable": bool(flags & 1),
            "voltage_limited": bool(flags & 2),
            "fault_step": fault_step,
        }
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
        d = check_reply(
            GET_CONFIG,
            self.request(GET_CONFIG, k if isinstance(k, bytes) else k[0] + k[1]),
            CONFIG_MIN_BYTES,
            text=True,
        )
        cid, ctype, flags, value = struct.unpack_from("<BBBf", d)
        try:
            name = d[7:].decode("ascii")
        except UnicodeDecodeError:
            raise MalformedReply(f"malformed CONFIG reply: the name of value {cid} is not ASCII") from None
        return {
            "id": cid,
            "name": name,
            "type": CONFIG_TYPES.get(ctype, "?"),
            "read_only": bool(flags & 1),
            "value": value,
        }

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
        p = {
            "status": status,
            "period": period,
            "position_rad": pos,
            "position_ref_rad": ref,
            "position_error_rad": err,
        }
        p.update({name: bool(flags & bit) for bit, name in POSITION_FLAGS.items()})
        return p

    def home(self, direction, travel_rad, speed_rad_s=0.0, stall_current_a=0.0):
        """Starts homing toward @p direction (+1, -1); raises DeviceError naming the code that refused it."""
        status, period = self._ack_status(
            HOME, struct.pack("<ffff", direction, speed_rad_s, travel_rad, stall_current_a)
        )
        if status != 0:
            raise DeviceError(f"the drive refused to home: {describe_code(status)}", status=status, request=HOME)
        return period

    def home_status(self):
        d = check_reply(HOME_STATUS, self.request(HOME_STATUS), HOME_STATUS_BYTES)
        status, period, state, by_current, stop, position = struct.unpack_from("<hIBBff", d)
        return {
            "status": status,
            "period": period,
            "state": HOMING_STATES.get(state, str(state)),
            "found_by": "stall current" if by_current else "following error",
            "stop_rad": stop,
            "position_rad": position,
        }

    # ---- the stored configuration ----
    def config_read(self, offset):
        """(offset, total, bytes) of the record of the configuration in force from @p offset
        (offset 0 encodes it anew)."""
        d = check_reply(CONFIG_READ, self.request(CONFIG_READ, struct.pack("<H", offset)), CONFIG_READ_MIN_BYTES)
        off, total = struct.unpack_from("<HH", d)
        return off, total, bytes(d[4:])

    def read_record(self):
        """The whole record of the configuration in force (CONFIG_READ from 0 to its end)."""
        data = bytearray()
        total = None
        while total is None or len(data) < total:
            off, tot, chunk = self.config_read(len(data))
            if off != len(data) or (total is not None and tot != total) or not chunk or len(data) + len(chunk) > tot:
                raise MalformedReply(
                    f"malformed CONFIG_READ reply: offset {off}, total {tot}, {len(chunk)} bytes "
                    f"after {len(data)} bytes read"
                )
            total = tot
            data += chunk
        return bytes(data)

    def config_write(self, offset, data):
        """Stages @p data at @p offset (0 starts a new record); @return the bytes staged."""
        d = check_reply(CONFIG_WRITE, self.request(CONFIG_WRITE, struct.pack("<H", offset) + bytes(data)), 2)
        return struct.unpack_from("<H", d)[0]

    def write_record(self, record):
        """Stages @p record in pieces as long as a frame carries; @return the number of pieces."""
        piece = MAX_PAYLOAD - 4  # TYPE, SEQ, offset u16
        pieces = 0
        for off in range(0, len(record), piece):
            chunk = record[off : off + piece]
            staged = self.config_write(off, chunk)
            if staged != off + len(chunk):
                raise DeviceError(f"CONFIG_WRITE: the drive staged {staged} bytes, expected {off + len(chunk)}")
            pieces += 1
        return pieces

    def config_apply(self):
        """Puts the staged record in force; raises DeviceError naming the code that refused it."""
        status, period = self._ack_status(CONFIG_APPLY)
        if status != 0:
            raise DeviceError(
                f"the drive refused the record: {describe_code(status)}; the configuration in force is unchanged",
                status=status,
                request=CONFIG_APPLY,
            )
        return period

    def _store_ack(self, ftype, doing):
        status, period = self._ack_status(ftype)
        if status != 0:
            raise DeviceError(f"{doing} failed: {describe_code(status)}", status=status, request=ftype)
        return period

    def config_save(self):
        return self._store_ack(CONFIG_SAVE, "saving")

    def config_erase(self):
        return self._store_ack(CONFIG_ERASE, "erasing")

    def config_defaults(self):
        return self._store_ack(CONFIG_DEFAULTS, "putting the board's defaults in force")

    def config_status(self):
        d = check_reply(CONFIG_STATUS, self.request(CONFIG_STATUS), CONFIG_STATUS_BYTES)
        (configured, boot, validation, last, slot, sequence, record_bytes, fmt, layout, board) = struct.unpack_from(
            "<BhhhbIHBII", d
        )
        return {
            "configured": bool(configured),
            "boot_status": boot,
            "boot_validation": validation,
            "last_status": last,
            "slot": slot,
            "sequence": sequence,
            "record_bytes": record_bytes,
            "record_format": fmt,
            "layout_id": layout,
            "board_id": board,
        }

    def calibrate(self, rated_current_a, pole_pairs=50, paper_mode=False, detent_fraction=0.05):
        """Starts self-commissioning; raises DeviceError naming the code that refused it."""
        data = struct.pack(
            "<fHBf", rated_current_a, pole_pairs, CALIBRATE_PAPER_MODE if paper_mode else 0, detent_fraction
        )
        status, period = self._ack_status(CALIBRATE, data)
        if status != 0:
            raise DeviceError(
                f"the drive refused to calibrate: {describe_code(status)}", status=status, request=CALIBRATE
            )
        return period

    def calibrate_status(self):
        d = check_reply(CALIBRATE_STATUS, self.request(CALIBRATE_STATUS), CALIBRATE_STATUS_BYTES)
        stage, status, fault, runs, ident, save, r, l, k, j, f = struct.unpack_from("<BhBBBh5f", d)
        return {
            "stage": CALIBRATE_STAGES.get(stage, str(stage)),
            "status": status,
            "fault": fault,
            "runs": runs,
            "identification": IDENTIFICATION.get(ident, str(ident)),
            "save_status": save,
            "resistance_Ohm": r,
            "inductance_H": l,
            "torque_constant_Nm_A": k,
            "inertia_kgm2": j,
            "friction_Nms_rad": f,
        }

    def sim_advance(self, periods, timeout=120.0):
        return self._ack(SIM_ADVANCE, struct.pack("<I", periods), timeout=timeout)

    def sim_finish(self):
        return self._ack(SIM_FINISH)

    def sim_steps(self, edges):
        """A simulation image's emulated STEP/DIR input: the STEP edges of each of the next len(@p edges)
        periods it runs (1 to SIM_STEPS_MAX of them, each -128..127, DIR by the sign), onto its 16-bit
        step counter. Answered at once; BUSY while edges of the last call remain."""
        if not 1 <= len(edges) <= SIM_STEPS_MAX or any(not -128 <= e <= 127 for e in edges):
            raise UsageError(f"SIM_STEPS takes 1 to {SIM_STEPS_MAX} periods of -128..127 edges")
        return self._ack(SIM_STEPS, struct.pack(f"<{len(edges)}b", *edges))

    def sim_follow_steps(self):
        """The STEP/DIR input started afresh at the counter's present value and the position loop on its
        count from the next period; DeviceError (status -2) while the position is not tracked."""
        return self._ack(SIM_FOLLOW_STEPS)

    def sim_stepdir(self):
        """The emulated STEP/DIR input: its count, the edges and the counter, its flags, the count's
        position and the following error (mechanical rad)."""
        d = check_reply(SIM_STEPDIR, self.request(SIM_STEPDIR), SIM_STEPDIR_BYTES)
        period, steps, edges, counter, flags, commanded, error = struct.unpack_from("<IiiHBff", d)
        s = {
            "period": period,
            "steps": steps,
            "edges": edges,
            "counter": counter,
            "commanded_rad": commanded,
            "following_error_rad": error,
        }
        s.update({name: bool(flags & bit) for bit, name in SIM_STEPDIR_FLAGS.items()})
        return s


# ---- names of status codes ----
_CORE_CODES = None


def core_status_codes():
    """{value: (name, meaning)} of pmstep_status_t, parsed at run time from the firmware's header
    with tools/gen_reference.py's parser (the same one the documentation uses), so that no list is
    copied here; {} when the sources are not next to this tool or do not parse (codes are then printed
    as numbers)."""
    global _CORE_CODES
    if _CORE_CODES is None:
        _CORE_CODES = {}
        header = "firmware/include/pmstep/pmstep_types.h"
        parser = Path(__file__).resolve().parent / "gen_reference.py"
        if (ROOT / header).is_file() and parser.is_file():
            try:
                spec = importlib.util.spec_from_file_location("pmstep_gen_reference", parser)
                module = importlib.util.module_from_spec(spec)
                sys.modules[spec.name] = module  # its dataclasses look their module up
                spec.loader.exec_module(module)
                values = module.parse_enum(module.Source(ROOT, header), "pmstep_status_t")
                values += module.parse_enum(
                    module.Source(ROOT, "firmware/design/include/pmstep/pmstep_calibrate.h"),
                    "pmstep_calibrate_status_t",
                )
                _CORE_CODES = {v.value: (v.name, v.doc) for v in values}
            except Exception:  # noqa: BLE001 - a parser or header of another shape: numbers only
                _CORE_CODES = {}
    return _CORE_CODES


def describe_code(code):
    """An ACK status with its name and meaning: a pmstep_store_status_t (-140..-151) or a
    pmstep_status_t, e.g. "status -22 (PMSTEP_ERR_INERTIA: J <= 0)"; a code without a known name
    as "status N"."""
    if code in STORE_CODES and code != 0:
        name, short, meaning = STORE_CODES[code]
        return f"status {code} ({name}, {short}: {meaning})"
    name, meaning = core_status_codes().get(code, (None, ""))
    if name is None:
        return f"status {code}"
    return f"status {code} ({name}" + (f": {meaning})" if meaning else ")")


def store_outcome(code):
    """A store status as the `store` command prints it, e.g. "another format (a record of another
    firmware; PMSTEP_STORE_ERR_FORMAT)"."""
    if code in STORE_CODES:
        name, short, meaning = STORE_CODES[code]
        return f"{short} ({meaning}; {name})" if code != 0 else f"ok ({name})"
    return describe_code(code)


# ---- the record of the stored configuration ----
def f32(x):
    """@p x rounded to float32 (as the drive keeps it); OverflowError beyond float32's range."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def f32_text(x):
    """The shortest text that reads back as the float32 @p x."""
    for digits in range(6, 10):
        text = f"{x:.{digits}g}"
        if f32(float(text)) == x:
            return text
    return repr(x)


class Record:
    """A record's fields (pmstep_store.h): header, values in table order, measured values."""

    def __init__(self, fmt, board_id, layout_id, sequence, values, measured):
        self.format = fmt
        self.board_id = board_id
        self.layout_id = layout_id
        self.sequence = sequence
        self.values = list(values)  # floats (float32 values)
        self.measured = dict(measured)  # MEASURED_FIELDS: flags int, the others float32 values

    def encode(self):
        """The record's bytes, CRC included. Every value must be a float32 (f32())."""
        n = RECORD_HEADER.size + 4 * len(self.values) + 4 * len(MEASURED_FIELDS) + 4
        body = RECORD_HEADER.pack(
            RECORD_MAGIC,
            self.format,
            RECORD_HEADER.size,
            self.board_id,
            self.layout_id,
            self.sequence,
            len(self.values),
            len(MEASURED_FIELDS),
            n,
            0,
        )
        body += struct.pack(f"<{len(self.values)}f", *self.values)
        body += struct.pack("<I7f", self.measured["flags"], *(self.measured[k] for k in MEASURED_FIELDS[1:]))
        return body + struct.pack("<I", zlib.crc32(body))

    @classmethod
    def decode(cls, data):
        """The fields of the record @p data; MalformedReply if it is none of this tool's format."""
        if len(data) < RECORD_HEADER.size + 4:
            raise MalformedReply(f"malformed record: {len(data)} bytes")
        magic, fmt, header, board, layout, seq, n, m, nbytes, _ = RECORD_HEADER.unpack_from(data)
        (crc,) = struct.unpack_from("<I", data, len(data) - 4)
        if magic != RECORD_MAGIC or nbytes != len(data) or zlib.crc32(data[:-4]) != crc:
            raise MalformedReply("malformed record: bad magic, length or CRC")
        if (
            fmt != RECORD_FORMAT
            or header != RECORD_HEADER.size
            or m != len(MEASURED_FIELDS)
            or nbytes != header + 4 * n + 4 * m + 4
        ):
            raise MalformedReply(
                f"record format {fmt} ({header}-byte header, {m} measured values): this tool "
                f"reads format {RECORD_FORMAT}; a newer pmstep_console.py is needed"
            )
        values = struct.unpack_from(f"<{n}f", data, header)
        flags, *rest = struct.unpack_from("<I7f", data, header + 4 * n)
        return cls(fmt, board, layout, seq, values, dict(zip(MEASURED_FIELDS, [flags] + rest)))


def layout_id(table):
    """The layout id of a configuration table (pmstep_store_layout_id()): CRC-32 of each name with its
    NUL and its type byte, in id order."""
    types = {v: k for k, v in CONFIG_TYPES.items()}
    crc = 0
    for e in table:
        if e["type"] not in types:
            raise MalformedReply(f"configuration value {e['name']} has a type this tool does not know")
        crc = zlib.crc32(e["name"].encode("ascii") + b"\0" + bytes([types[e["type"]]]), crc)
    return crc


def typed(entry, value):
    """A table value as its type gives it: int for u32/i32, bool, float for f32."""
    if entry["type"] == "bool":
        return value != 0.0
    if entry["type"] in ("u32", "i32"):
        return int(value)
    return float(f32_text(value))


def to_entry_value(entry, value, what):
    """@p value (a number, or a bool for a boolean entry) as the float32 the record holds for
    @p entry; ConfigurationRefused naming @p what when the entry cannot take it."""
    name, kind = entry["name"], entry["type"]
    if isinstance(value, bool):
        if kind != "bool":
            raise ConfigurationRefused(f"{what} {name} = {value}: a boolean for a {kind} value")
        return 1.0 if value else 0.0
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigurationRefused(f"{what} {name} = {value!r}: not a finite number")
    try:
        v = f32(value)
    except OverflowError:
        raise ConfigurationRefused(f"{what} {name} = {value!r}: beyond float32's range") from None
    if kind == "bool" and v not in (0.0, 1.0):
        raise ConfigurationRefused(f"{what} {name} = {value!r}: a boolean is 0 or 1 (false or true)")
    if kind in ("u32", "i32") and (v != math.floor(v) or (kind == "u32" and v < 0)):
        raise ConfigurationRefused(f"{what} {name} = {value!r}: not a whole number{' >= 0' if kind == 'u32' else ''}")
    return v


class Board:
    """What a drive with a store holds: HELLO, the record of the configuration in force (raw and
    decoded) and its configuration table (GET_CONFIG by id: name, type, read-only)."""

    def __init__(self, hello, raw, record, table):
        self.hello = hello
        self.raw = raw
        self.record = record
        self.table = table
        self.index = {e["name"]: i for i, e in enumerate(table)}

    def value(self, name):
        return self.record.values[self.index[name]]

    def typed_values(self, values=None):
        values = self.record.values if values is None else values
        return {e["name"]: typed(e, v) for e, v in zip(self.table, values)}


def read_board(con):
    """The board's record and table; DeviceError if the drive has no store. The table read by id must
    give the record's layout id (else the names would not be the values' own)."""
    hello = con.hello()
    if hello["protocol"] < 2 or not hello["store"]:
        raise DeviceError(
            f"this drive keeps no stored configuration (protocol {hello['protocol']}"
            f"{', no store attached' if hello['protocol'] >= 2 else ''}): {hello['identity']}",
            code=11,
        )
    raw = con.read_record()
    record = Record.decode(raw)
    table = [con.get_config(i) for i in range(len(record.values))]
    if layout_id(table) != record.layout_id:
        raise MalformedReply(
            f"the configuration table read by id (layout 0x{layout_id(table):08x}) is not the "
            f"record's (layout 0x{record.layout_id:08x})"
        )
    for e, v in zip(table, record.values):
        if f32(e["value"]) != v:
            raise MalformedReply(f"the record and GET_CONFIG disagree on {e['name']}: {v!r} and {e['value']!r}")
    return Board(hello, raw, record, table)


def require_idle(con, doing):
    """DeviceError unless the motor is IDLE (a record is applied only there): before any work."""
    mode = con.status()["mode"]
    if mode != "IDLE":
        raise DeviceError(
            f"{doing} needs the motor stopped (IDLE), it is in {mode}: "
            f"`{'clear' if mode == 'FAULT' else 'stop'}` first",
            code=6,
        )


def put_record(con, board, record):
    """Writes @p record in pieces, applies it, reads it back and compares it field by field with what
    was written. @return (pieces, the record read back). Raises DeviceError for a refusal (its code
    by name), ConfigurationRefused listing the fields that differ."""
    data = record.encode()
    pieces = con.write_record(data)
    con.config_apply()
    back = Record.decode(con.read_record())
    diffs = []
    for field in ("format", "board_id", "layout_id", "sequence"):
        if getattr(back, field) != getattr(record, field):
            diffs.append(f"{field}: written {getattr(record, field)}, read {getattr(back, field)}")
    if len(back.values) != len(record.values):
        diffs.append(f"value count: written {len(record.values)}, read {len(back.values)}")
    for e, w, r in zip(board.table, record.values, back.values):
        if struct.pack("<f", w) != struct.pack("<f", r):
            diffs.append(f"{e['name']}: written {f32_text(w)}, read {f32_text(r)}")
    for k in MEASURED_FIELDS:
        if struct.pack("<f" if k != "flags" else "<I", record.measured[k]) != struct.pack(
            "<f" if k != "flags" else "<I", back.measured[k]
        ):
            diffs.append(f"measured {k}: written {record.measured[k]}, read {back.measured[k]}")
    if diffs:
        raise ConfigurationRefused("the record read back differs from the one written:\n  " + "\n  ".join(diffs))
    return pieces, back


def print_stored(con, board, record, save):
    """Saves (if @p save) and prints the slot, the sequence and every value by name."""
    if save:
        con.config_save()
        st = con.config_status()
        print(f"saved: slot {st['slot']}, sequence {st['sequence']}")
    else:
        print("in force, not saved: `save` stores it (a reset brings back the stored configuration)")
    for e, v in zip(board.table, record.values):
        print(f"  {e['name']:44s} = {typed_text(e, v)}" + ("  (read-only)" if e["read_only"] else ""))


def typed_text(entry, value):
    t = typed(entry, value)
    return ("true" if t else "false") if isinstance(t, bool) else (str(t) if isinstance(t, int) else f32_text(value))


# ---- setup: a design of pmstep-tune onto the board's table ----
# The board's read-only values and the scenario keys that give them to pmstep-tune (sil/src/scenario_keys.c:
# run.period_s and run.delay_periods are the controller's timing; the sense ranges are the sensors' full
# scales, sil_scenario_sense_ranges()).
READ_ONLY_SCENARIO_KEYS = {
    "timing.period_s": "run.period_s",
    "timing.computational_delay_periods": "run.delay_periods",
    "limits.current_sense_range_A": "sensors.current_full_scale_A",
    "limits.bus_sense_range_V": "sensors.bus_full_scale_V",
}
BUS_VOLTAGE_KEY = "run.bus_voltage_V"
DEFAULT_TUNE = "build/host-release/sil/pmstep-tune"


def find_tune(option):
    """The pmstep-tune to run: @p option (--tune), else $PMSTEP_TUNE, else DEFAULT_TUNE of this tree."""
    if option:
        path, origin = Path(option), "--tune"
    elif os.environ.get("PMSTEP_TUNE"):
        path, origin = Path(os.environ["PMSTEP_TUNE"]), "$PMSTEP_TUNE"
    else:
        path, origin = ROOT / DEFAULT_TUNE, "the default"
    if not path.is_file() or not os.access(path, os.X_OK):
        raise UsageError(
            f"pmstep-tune not found at {path} ({origin}): build it (cmake --preset host-release && "
            f"cmake --build --preset host-release --target pmstep-tune) or give its path with --tune "
            f"or $PMSTEP_TUNE"
        )
    return path


def read_design(path):
    """The designed values of a scenario written by pmstep-tune --write-ini: (by table name, the
    scenario's keys). [controller.SECTION] KEY is the table's SECTION.KEY, [controller] KEY is KEY."""
    cp = configparser.ConfigParser(interpolation=None, comment_prefixes=(";", "#"), inline_comment_prefixes=None)
    cp.optionxform = str  # the names are case-sensitive (resistance_Ohm)
    try:
        cp.read(path, encoding="utf-8")
    except configparser.Error as e:
        raise ConfigurationRefused(f"pmstep-tune's design {path} does not read: {e}") from e
    design, keys = {}, {}
    for section in cp.sections():
        for key, text in cp.items(section):
            keys[f"{section}.{key}"] = text
            if section == "controller" or section.startswith("controller."):
                prefix = section[len("controller.") :] + "." if section != "controller" else ""
                design[prefix + key] = text
    return design, keys


def design_number(name, text):
    """A designed value's text as a number (true/false as 1/0)."""
    if text in ("true", "false"):
        return 1.0 if text == "true" else 0.0
    try:
        return float(text)
    except ValueError:
        raise ConfigurationRefused(f"pmstep-tune designed {name} = {text!r}: not a number") from None


def preset_bus_voltage(path):
    """Whether the motor preset @p path gives run.bus_voltage_V (else pmstep-tune's default applies)."""
    cp = configparser.ConfigParser(interpolation=None, comment_prefixes=(";", "#"), strict=False)
    cp.optionxform = str
    try:
        cp.read(path, encoding="utf-8")
    except (configparser.Error, UnicodeDecodeError):
        return False
    return cp.has_option("run", "bus_voltage_V")


def setup(con, a):
    """The setup command (module docstring): design, map onto the board's table, write, apply, read
    back, compare, save; prints each step."""
    if bool(a.motor) == bool(a.motor_db):
        raise UsageError("setup: give --motor MOTOR.ini, or --motor-db FILE --name NAME")
    if a.motor_db and not a.name:
        raise UsageError("setup: --motor-db needs --name NAME (a [motor_constants NAME] section)")
    for path in filter(None, (a.motor, a.motor_db)):
        if not Path(path).is_file():
            raise UsageError(f"setup: {path}: no such file")
    sets = list(a.set or [])
    for s in sets:
        key = s.split("=", 1)[0].strip()
        if "=" not in s:
            raise UsageError(f"setup: --set {s}: expected SECTION.KEY=VALUE")
        if key in READ_ONLY_SCENARIO_KEYS.values():
            raise UsageError(f"setup: --set {key}: the board's own value (read-only), the design uses the board's")
        if key == BUS_VOLTAGE_KEY and a.bus_voltage is not None:
            raise UsageError(f"setup: --bus-voltage and --set {BUS_VOLTAGE_KEY} both given")
    if a.bus_voltage is not None and not (math.isfinite(a.bus_voltage) and a.bus_voltage > 0):
        raise UsageError(f"setup: --bus-voltage {a.bus_voltage}: expected a voltage > 0")
    tune = find_tune(a.tune)
    board = read_board(con)
    require_idle(con, "setup")
    h, r = board.hello, board.record
    print(
        f"board: {h['identity']}, record format {r.format}, board id 0x{r.board_id:08x}, layout 0x{r.layout_id:08x}, "
        f"{len(r.values)} values; {'a motor configured' if h['configured'] else 'no motor configured'}"
    )
    # The board's read-only values go to pmstep-tune as the scenario's: the design is made for them.
    board_sets = []
    for e in board.table:
        if e["read_only"]:
            if e["name"] not in READ_ONLY_SCENARIO_KEYS:
                raise ConfigurationRefused(
                    f"the board's read-only value {e['name']} has no scenario key this tool "
                    "knows: a design for it cannot be made (a newer pmstep_console.py?)"
                )
            v = typed(e, board.value(e["name"]))
            board_sets.append(f"{READ_ONLY_SCENARIO_KEYS[e['name']]}={v!r}")
    if a.bus_voltage is not None:
        sets.append(f"{BUS_VOLTAGE_KEY}={a.bus_voltage!r}")
    with tempfile.TemporaryDirectory(prefix="pmstep-setup-") as tmp:
        ini = os.path.join(tmp, "design.ini")
        argv = [str(tune)] + (["--motor", a.motor] if a.motor else ["--motor-db", a.motor_db, "--name", a.name])
        argv += ["--robust"] if a.robust else []
        for s in board_sets + sets:
            argv += ["--set", s]
        argv += ["--write-ini", ini]
        print("design: " + " ".join(shlex.quote(x) for x in argv[:-2]))
        try:
            run = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=300)
        except (OSError, subprocess.TimeoutExpired) as e:
            raise UsageError(f"pmstep-tune could not run: {e}") from e
        for line in run.stdout.splitlines():
            print(f"  | {line}")
        if run.returncode != 0:
            cls = UsageError if run.returncode == 2 else ConfigurationRefused
            raise cls(f"pmstep-tune refused the design (exit {run.returncode}); nothing written to the board")
        design, keys = read_design(ini)
    # The read-only values of the design must be the board's (they were given with --set).
    for e in board.table:
        if e["read_only"]:
            key = READ_ONLY_SCENARIO_KEYS[e["name"]]
            text = keys.get(key)
            if text is None or f32(design_number(key, text)) != board.value(e["name"]):
                raise ConfigurationRefused(
                    f"pmstep-tune designed for {key} = {text}, the board's {e['name']} is "
                    f"{f32_text(board.value(e['name']))}"
                )
    bus_text = keys.get(BUS_VOLTAGE_KEY, "?")
    if a.bus_voltage is not None:
        origin = "--bus-voltage"
    elif any(s.split("=", 1)[0].strip() == BUS_VOLTAGE_KEY for s in sets):
        origin = f"--set {BUS_VOLTAGE_KEY}"
    elif a.motor and preset_bus_voltage(a.motor):
        origin = f"the motor preset's {BUS_VOLTAGE_KEY}"
    else:
        origin = "pmstep-tune's default: " + ("the preset gives none" if a.motor else "a motor database gives none")
    print(
        "designed for the board's "
        + ", ".join(f"{e['name']} = {typed_text(e, board.value(e['name']))}" for e in board.table if e["read_only"])
        + f"; bus {bus_text} V ({origin})"
    )
    # Onto the board's table by name: every value the board can take from the design.
    values = list(r.values)
    kept = []
    for i, e in enumerate(board.table):
        if e["read_only"]:
            continue
        if e["name"] in design:
            values[i] = to_entry_value(e, design_number(e["name"], design[e["name"]]), "designed")
        else:
            kept.append(e["name"])
    unused = [n for n in design if n not in board.index]
    if unused:
        print("designed, not on this board (not written): " + ", ".join(unused))
    if kept:
        which = "the board's default" if not h["configured"] else "the value in force"
        print(
            f"not in the design, {which} kept: "
            + ", ".join(f"{n} = {typed_text(board.table[board.index[n]], r.values[board.index[n]])}" for n in kept)
        )
    # Nothing measured on this motor yet: a design from its data.
    record = Record(
        r.format, r.board_id, r.layout_id, 0, values, {k: (0 if k == "flags" else 0.0) for k in MEASURED_FIELDS}
    )
    pieces, back = put_record(con, board, record)
    print(f"record: {len(record.encode())} bytes written in {pieces} pieces, applied, read back equal")
    print_stored(con, board, back, save=True)


# ---- backup and restore ----
def backup(con):
    """The board's configuration as a JSON-able dict (the backup file's contents)."""
    board = read_board(con)
    r = board.record
    measured = {k: (v if k == "flags" else float(f32_text(v))) for k, v in r.measured.items()}
    return {
        "identity": board.hello["identity"],
        "protocol": board.hello["protocol"],
        "configured": board.hello["configured"],
        "record_format": r.format,
        "board_id": r.board_id,
        "layout_id": r.layout_id,
        "values": board.typed_values(),
        "read_only": [e["name"] for e in board.table if e["read_only"]],
        "measured": measured,
        "record": board.raw.hex(),
    }


def load_backup(path):
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except OSError as e:
        raise UsageError(f"cannot read {path}: {e.strerror}") from e
    except ValueError as e:
        raise UsageError(f"{path} is not JSON: {e}") from e
    if not isinstance(data, dict) or not isinstance(data.get("values"), dict):
        raise UsageError(f'{path} is no backup of pmstep_console.py: no "values" by name')
    measured = data.get("measured")
    if measured is not None and (not isinstance(measured, dict) or set(measured) != set(MEASURED_FIELDS)):
        raise UsageError(f'{path}: "measured" must have the fields {", ".join(MEASURED_FIELDS)}')
    return data


def restore(con, path, save):
    """The restore command (module docstring)."""
    data = load_backup(path)
    board = read_board(con)
    require_idle(con, "restore")
    r = board.record
    unknown = [n for n in data["values"] if n not in board.index]
    if unknown:
        raise ConfigurationRefused(
            "the backup has values this board does not: " + ", ".join(unknown) + "; nothing written"
        )
    differ = []
    for name, v in data["values"].items():
        e = board.table[board.index[name]]
        if e["read_only"] and (
            isinstance(v, bool)
            or not isinstance(v, (int, float))
            or to_entry_value(e, v, "backup") != board.value(name)
        ):
            differ.append(f"{name} (backup {v}, board {typed_text(e, board.value(name))})")
    if differ:
        raise ConfigurationRefused(
            "the backup was made for other read-only values: " + ", ".join(differ) + "; nothing written"
        )
    if data.get("board_id") is not None and data["board_id"] != r.board_id:
        print(f"note: the backup was made on board id 0x{data['board_id']:08x}, this board is 0x{r.board_id:08x}")
    values = list(r.values)
    for name, v in data["values"].items():
        e = board.table[board.index[name]]
        if not e["read_only"]:
            values[board.index[name]] = to_entry_value(e, v, "backup value")
    missing = [e["name"] for e in board.table if e["name"] not in data["values"]]
    if missing:
        print("not in the backup, the value in force kept: " + ", ".join(missing))
    measured = {k: 0 if k == "flags" else 0.0 for k in MEASURED_FIELDS}
    if data.get("measured") is not None:
        for k, v in data["measured"].items():
            if k == "flags":
                if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v < 2**32:
                    raise ConfigurationRefused(f"backup measured flags = {v!r}: not a 32-bit whole number")
                measured[k] = v
            else:
                measured[k] = to_entry_value({"name": k, "type": "f32"}, v, "backup measured")
    else:
        print("note: the backup has no measured values: restored as not measured")
    record = Record(r.format, r.board_id, r.layout_id, 0, values, measured)
    pieces, back = put_record(con, board, record)
    print(f"restored {path}: {len(record.encode())} bytes written in {pieces} pieces, applied, read back equal")
    print_stored(con, board, back, save)


FAULTS = {
    0: "none",
    1: "MEASUREMENT_NONFINITE",
    2: "OVERCURRENT",
    3: "BUS_UNDERVOLTAGE",
    4: "BUS_OVERVOLTAGE",
    5: "STATE_NONFINITE",
    6: "ANGLE_MAGNITUDE",
    7: "SPEED_INCONSISTENT",
    8: "STALL",
    9: "COMMISSIONING",
    10: "OBSERVER_RESIDUAL",
    11: "PHASE_VOLTAGE_RANGE",
    12: "ALIGNMENT_MOTION",
    13: "OPEN_PHASE_A",
    14: "OPEN_PHASE_B",
    15: "CURRENT_STUCK_A",
    16: "CURRENT_STUCK_B",
    17: "ESTIMATE_RANGE",
}


def home(con, a):
    """HOME, then HOME_STATUS every tenth of a second (a simulation image: --advance periods of its time
    each) until the homing is over; where the stop was found and the outcome printed."""
    if len(a.args) != 1 or a.args[0] not in ("+", "-") or a.travel is None:
        raise UsageError("home +|- --travel RAD [--speed RAD_S] [--stall-current A] [--timeout S] [--advance N]")
    direction = 1.0 if a.args[0] == "+" else -1.0
    con.home(direction, a.travel, a.speed or 0.0, a.stall_current or 0.0)
    print(f"homing toward {a.args[0]}, at most {a.travel} rad" + (f" at {a.speed} rad/s" if a.speed else ""))
    deadline = time.monotonic() + a.timeout
    last = None
    while True:
        if a.advance:
            con.sim_advance(a.advance, timeout=600.0)
        else:
            con.pump(0.1)
        st = con.home_status()
        if st["state"] != last:
            print(f"  {st['state']:12s} position {st['position_rad']:+.5f} rad")
            last = st["state"]
        if st["state"] not in ("seeking", "backing off"):
            break
        if time.monotonic() > deadline:
            con.hold(None)
            raise DeviceError(f"homing not over after {a.timeout:.0f} s: holding where it is")
    if st["state"] != "done":
        raise DeviceError(
            f"homing {st['state']}: "
            + {
                "not found": f"no stop within {a.travel} rad; the drive holds at the end of the travel",
                "aborted": "the drive left RUN or another command took over",
            }.get(st["state"], "not started")
        )
    print(
        f"home: the stop found by the {st['found_by']} at {st['stop_rad']:+.5f} rad; it is the zero now, the "
        f"rotor at {st['position_rad']:+.5f} rad"
    )


def calibrate(con, a):
    """CALIBRATE, then CALIBRATE_STATUS every half second (a simulation image: --advance periods of its
    time each) until it is done or failed; the measured motor and the outcome printed."""
    if a.current is None:
        raise UsageError("calibrate --current RATED_A [--pole-pairs P] [--paper] [--detent-fraction D] [--timeout S]")
    require_idle(con, "calibrating")
    con.calibrate(a.current, a.pole_pairs, a.paper, a.detent_fraction)
    print(
        f"calibrating from I = {a.current} A, p = {a.pole_pairs}, detent {a.detent_fraction} of the holding torque, "
        f"{'paper' if a.paper else 'robust'} mode"
    )
    deadline = time.monotonic() + a.timeout
    last = None
    while True:
        if a.advance:
            con.sim_advance(a.advance, timeout=600.0)
        else:
            con.pump(0.5)
        st = con.calibrate_status()
        line = (
            f"  {st['stage']:11s} run {st['runs']}: R {st['resistance_Ohm']:.4g} Ohm, L {st['inductance_H']:.4g} H, "
            f"k_M {st['torque_constant_Nm_A']:.4g} N m/A, J {st['inertia_kgm2']:.4g} kg m^2"
        )
        if line != last:
            print(line)
            last = line
        if st["stage"] in ("done", "failed"):
            break
        if time.monotonic() > deadline:
            con.stop()
            raise DeviceError(f"calibration not over after {a.timeout:.0f} s: stopped")
    if st["stage"] == "failed":
        fault = f"; the run ended in {FAULTS.get(st['fault'], st['fault'])}" if st["fault"] else ""
        raise DeviceError(
            f"calibration failed: {describe_code(st['status'])}{fault}; the board's defaults are in "
            "force, no motor configured",
            status=st["status"],
            request=CALIBRATE,
        )
    # The design is saved at the first boundary with the bridge off: wait for the drive to say so.
    for _ in range(20):
        if st["save_status"] != 0 or con.config_status()["configured"] and con.config_status()["slot"] >= 0:
            break
        if a.advance:
            con.sim_advance(10, timeout=60.0)
        else:
            con.pump(0.1)
        st = con.calibrate_status()
    print(
        f"calibrated: R {st['resistance_Ohm']:.5g} Ohm, L {st['inductance_H']:.5g} H, "
        f"k_M {st['torque_constant_Nm_A']:.5g} N m/A, J {st['inertia_kgm2']:.5g} kg m^2, "
        f"F {st['friction_Nms_rad']:.4g} N m s/rad (identification {st['identification']}, {st['runs']} runs)"
    )
    if st["save_status"] != 0:
        raise DeviceError(
            f"the calibrated design is in force but was not saved: {describe_code(st['save_status'])}",
            status=st["save_status"],
            request=CALIBRATE,
        )
    store = con.config_status()
    print(f"saved: slot {store['slot']}, sequence {store['sequence']}")


def print_store(con):
    st = con.config_status()
    print(f"  {'configured':26s} {'yes' if st['configured'] else 'no (START refused until setup or restore)'}")
    print(f"  {'boot':26s} {store_outcome(st['boot_status'])}")
    if st["boot_validation"] != 0:
        print(f"  {'boot refused by the core':26s} {describe_code(st['boot_validation'])}")
    print(f"  {'last save/erase/apply':26s} {store_outcome(st['last_status'])}")
    print(f"  {'slot':26s} {st['slot'] if st['slot'] >= 0 else 'none (no valid record)'}")
    print(f"  {'sequence':26s} {st['sequence']}")
    print(f"  {'record bytes':26s} {st['record_bytes']}")
    print(f"  {'record format':26s} {st['record_format']}")
    print(f"  {'layout id':26s} 0x{st['layout_id']:08x}")
    print(f"  {'board id':26s} 0x{st['board_id']:08x}")


NOT_CONFIGURED_HELP = (
    "the drive has no motor configured (error 10): configure it first - `setup --motor MOTOR.ini` "
    "(or `setup --motor-db FILE --name NAME`) designs, writes and saves one from the motor's data, "
    "`restore BACKUP.json --save` brings back a backup, or the drive calibrates the motor itself "
    "(CALIBRATE, on images with self-commissioning)"
)


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


PLOTS = [
    ("speed_hat_rad_s", "speed_ref_rad_s", "rad/s"),
    ("load_hat_Nm", None, "Nm"),
    ("i_a_A", "i_b_A", "A"),
    ("cos_hat", "sin_hat", ""),
]


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
    p.add_argument("--motor")
    p.add_argument("--motor-db")
    p.add_argument("--name")
    p.add_argument("--robust", action="store_true")
    p.add_argument("--set", action="append")
    p.add_argument("--bus-voltage", type=float)
    p.add_argument("--tune")
    p.add_argument("--save", action="store_true")
    p.add_argument("--current", type=float)
    p.add_argument("--pole-pairs", type=int, default=50)
    p.add_argument("--paper", action="store_true")
    p.add_argument("--detent-fraction", type=float, default=0.05)
    p.add_argument("--travel", type=float)
    p.add_argument("--speed", type=float)
    p.add_argument("--stall-current", type=float)
    p.add_argument("--timeout", type=float, default=120.0)
    p.add_argument("--advance", type=int, default=0)
    a = p.parse_args(argv)
    w = a.what
    if w == "hello":
        print_dict(con.hello())
    elif w == "start":
        try:
            print(f"start: done from period {con.start()}")
        except DeviceError as e:
            if e.code == ERR_NOT_CONFIGURED:
                raise DeviceError(NOT_CONFIGURED_HELP, code=e.code, request=e.request) from None
            raise
    elif w == "status":
        print_dict(con.status())
    elif w == "counters":
        print_dict(con.counters())
    elif w == "commissioning":
        print_dict(con.commissioning())
    elif w in ("stop", "clear"):
        period = {"stop": con.stop, "clear": con.clear_fault}[w]()
        print(f"{w}: done from period {period}")
    elif w == "speed":
        print(f"speed target {a.args[0]} rad/s at {a.ramp} rad/s^2: from period {con.speed(float(a.args[0]), a.ramp)}")
    elif w == "id":
        print(f"i_d target {a.args[0]} A: from period {con.id_target(float(a.args[0]))}")
    elif w == "config":
        for c in con.list_config():
            ro = " (read-only)" if c["read_only"] else ""
            print(f"  {c['id']:3d} {c['name']:44s} {f32_text(c['value']):15s} {c['type']}{ro}")
    elif w == "get":
        c = con.get_config(a.args[0])
        print(f"  {c['id']} {c['name']} = {f32_text(c['value'])} ({c['type']})")
    elif w == "set":
        print(
            f"set {a.args[0]} = {a.args[1]}: done (core re-initialised) "
            f"at period {con.set_config(a.args[0], a.args[1])}"
        )
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
    elif w == "setup":
        setup(con, a)
    elif w == "backup":
        if len(a.args) != 1:
            raise UsageError("backup FILE.json")
        data = backup(con)
        try:
            with open(a.args[0], "w", encoding="utf-8") as f:
                json.dump(data, f, indent=1)
                f.write("\n")
        except OSError as e:
            raise UsageError(f"cannot write {a.args[0]}: {e.strerror}") from e
        print(
            f"backup of {data['identity']} (board id 0x{data['board_id']:08x}, record format "
            f"{data['record_format']}, {len(data['values'])} values, "
            f"{'a motor' if data['configured'] else 'no motor'} configured) written to {a.args[0]}"
        )
    elif w == "restore":
        if len(a.args) != 1:
            raise UsageError("restore FILE.json [--save]")
        restore(con, a.args[0], a.save)
    elif w == "save":
        try:
            con.config_save()
        except DeviceError as e:
            if e.code == ERR_NOT_CONFIGURED:
                raise DeviceError("nothing to save: " + NOT_CONFIGURED_HELP, code=e.code, request=e.request) from None
            raise
        st = con.config_status()
        print(f"saved: slot {st['slot']}, sequence {st['sequence']}")
    elif w == "erase":
        con.config_erase()
        con.config_defaults()
        print("erased: both flash slots; the board's defaults in force, no motor configured")
    elif w == "defaults":
        con.config_defaults()
        print(
            "the board's defaults in force, no motor configured; the flash untouched (a reset brings back the "
            "stored configuration)"
        )
    elif w == "store":
        print_store(con)
    elif w == "calibrate":
        calibrate(con, a)
    elif w == "home":
        home(con, a)
    else:
        return False
    return True


class Shell(cmd.Cmd):
    intro = (
        "pmstep console: hello, status, start, stop, clear, speed T [--ramp R], id A, config, get K, "
        "set K V, commissioning, counters, telemetry [--decimation N --seconds S --csv F --plot], "
        "move X [--vmax V --amax A --jmax J], hold [--amax A], position, zero, "
        "home +|- --travel X [--speed V --stall-current A], setup (--motor F | "
        "--motor-db F --name N) [--robust --set K=V --bus-voltage V --tune P], backup F, restore F [--save], "
        "save, erase, defaults, store, calibrate --current A [--pole-pairs P --paper --detent-fraction D], quit"
    )
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
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__
    )
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
