"""Run an FMI 2.0 co-simulation FMU from Python: a small importer over ctypes and the standard
library (zipfile, xml.etree), independent of the hystlab C++ library.

    import hystlab.fmu
    with hystlab.fmu.Fmu("T.fmu") as f:
        f.initialize(x=0.0)              # parameters and the input's start, then initialized
        for x in path:
            f.set(x=x)
            f.do_step(h=1e-3)
            force = f.get("F")
        s = f.get_state(); ...; f.set_state(s)          # roll back
        blob = f.serialize(s); s2 = f.deserialize(blob)  # keep a state as bytes

It reads any co-simulation FMU with a linux64 binary: hystlab's own (docs/FORMATS.md "FMU"), or
another tool's. A call that the FMU refuses raises FmuError with the message the FMU logged.
"""
import ctypes
import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
import zipfile

__all__ = ["Fmu", "FmuError", "FmuState"]

_OK, _WARNING = 0, 1
_STATUS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]
_CO_SIMULATION = 1

# The logger is C-variadic. FMUs pass the message as a format and arguments; on x86-64 the first
# variadic argument arrives where a sixth fixed argument would, so hystlab's "%s", message is read
# whole. Another FMU's message is shown as its format when it uses other conversions.
_Logger = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                           ctypes.c_char_p, ctypes.c_char_p)


class _Callbacks(ctypes.Structure):
    _fields_ = [("logger", _Logger), ("allocateMemory", ctypes.c_void_p), ("freeMemory", ctypes.c_void_p),
                ("stepFinished", ctypes.c_void_p), ("componentEnvironment", ctypes.c_void_p)]


class FmuError(RuntimeError):
    """A call the FMU refused (the message is what it logged), or an archive that is not an FMU."""


class FmuState:
    """A state got from an instance (fmi2GetFMUstate); freed with the instance or by free()."""

    def __init__(self, fmu, handle, time):
        self._fmu, self.handle, self.time = fmu, handle, time

    def free(self):
        if self.handle and self._fmu._c:
            h = ctypes.c_void_p(self.handle)
            self._fmu._lib.fmi2FreeFMUstate(self._fmu._c, ctypes.byref(h))
            self._fmu._states.discard(self)
        self.handle = None


class Variable:
    def __init__(self, sv):
        self.name = sv.get("name")
        self.vr = int(sv.get("valueReference"))
        self.causality = sv.get("causality", "local")
        self.variability = sv.get("variability", "continuous")
        kind = next((c for c in sv if c.tag in ("Real", "Integer", "Boolean", "String", "Enumeration")), None)
        if kind is None:
            raise FmuError("variable %r has no type element" % self.name)
        self.type = kind.tag
        self.unit = kind.get("unit", "")
        self.start = kind.get("start")

    def __repr__(self):
        return "Variable(%s, vr=%d, %s %s %s)" % (self.name, self.vr, self.causality, self.type, self.unit)


class Fmu:
    """One instance of a co-simulation FMU, unpacked into a temporary folder until close()."""

    def __init__(self, path, instance_name="hystlab", logging=False):
        self.messages = []
        self._c = None
        self._dir = tempfile.mkdtemp(prefix="hystlab-fmu-")
        self._states = set()
        try:
            self._unpack(path)
            self._load()
            self._instantiate(instance_name, logging)
        except BaseException:
            self.close()
            raise
        self.time = 0.0
        self._initialized = False

    # -- the archive ----------------------------------------------------------------------------
    def _unpack(self, path):
        try:
            with zipfile.ZipFile(path) as z:
                for name in z.namelist():  # no entry may leave the folder
                    target = os.path.realpath(os.path.join(self._dir, name))
                    if not target.startswith(os.path.realpath(self._dir) + os.sep):
                        raise FmuError("%s: entry %r lies outside the archive's folder" % (path, name))
                z.extractall(self._dir)
        except zipfile.BadZipFile as e:
            raise FmuError("%s: not an FMU (not a ZIP archive: %s)" % (path, e)) from None
        try:
            root = ET.parse(os.path.join(self._dir, "modelDescription.xml")).getroot()
        except (OSError, ET.ParseError) as e:
            raise FmuError("%s: modelDescription.xml: %s" % (path, e)) from None
        if root.get("fmiVersion") != "2.0":
            raise FmuError("%s: fmiVersion %r (this importer runs FMI 2.0)" % (path, root.get("fmiVersion")))
        cs = root.find("CoSimulation")
        if cs is None:
            raise FmuError("%s: not a co-simulation FMU (no <CoSimulation>)" % path)
        self.guid = root.get("guid")
        self.model_name = root.get("modelName")
        self.description = root.get("description", "")
        self.identifier = cs.get("modelIdentifier")
        self.capabilities = dict(cs.attrib)
        self.variables = {v.name: v for v in map(Variable, root.iter("ScalarVariable"))}

    def _load(self):
        so = os.path.join(self._dir, "binaries", "linux64", self.identifier + ".so")
        if not os.path.exists(so):
            raise FmuError("the FMU has no binary for linux64 (%s)" % os.path.relpath(so, self._dir))
        self._lib = ctypes.CDLL(so, mode=ctypes.RTLD_LOCAL)
        L, c_void_p, c_size_t = self._lib, ctypes.c_void_p, ctypes.c_size_t
        vrs, dbl, integer = ctypes.POINTER(ctypes.c_uint), ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int)
        L.fmi2Instantiate.restype = c_void_p
        L.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                                      ctypes.POINTER(_Callbacks), ctypes.c_int, ctypes.c_int]
        L.fmi2FreeInstance.argtypes = [c_void_p]
        L.fmi2FreeInstance.restype = None
        for name, args in {
                "fmi2SetupExperiment": [c_void_p, ctypes.c_int, ctypes.c_double, ctypes.c_double, ctypes.c_int, ctypes.c_double],
                "fmi2EnterInitializationMode": [c_void_p], "fmi2ExitInitializationMode": [c_void_p],
                "fmi2Terminate": [c_void_p], "fmi2Reset": [c_void_p],
                "fmi2GetReal": [c_void_p, vrs, c_size_t, dbl], "fmi2SetReal": [c_void_p, vrs, c_size_t, dbl],
                "fmi2GetInteger": [c_void_p, vrs, c_size_t, integer], "fmi2SetInteger": [c_void_p, vrs, c_size_t, integer],
                "fmi2SetRealInputDerivatives": [c_void_p, vrs, c_size_t, integer, dbl],
                "fmi2DoStep": [c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int],
                "fmi2GetFMUstate": [c_void_p, ctypes.POINTER(c_void_p)], "fmi2SetFMUstate": [c_void_p, c_void_p],
                "fmi2FreeFMUstate": [c_void_p, ctypes.POINTER(c_void_p)],
                "fmi2SerializedFMUstateSize": [c_void_p, c_void_p, ctypes.POINTER(c_size_t)],
                "fmi2SerializeFMUstate": [c_void_p, c_void_p, ctypes.c_char_p, c_size_t],
                "fmi2DeSerializeFMUstate": [c_void_p, ctypes.c_char_p, c_size_t, ctypes.POINTER(c_void_p)]}.items():
            f = getattr(L, name)
            f.argtypes, f.restype = args, ctypes.c_int

    def _instantiate(self, name, logging):
        def log(_env, _instance, status, category, message, first_arg):
            text = (message or b"").decode("utf-8", "replace")
            if text == "%s" and first_arg is not None:
                text = first_arg.decode("utf-8", "replace")
            self.messages.append((_STATUS[status] if 0 <= status < len(_STATUS) else str(status),
                                  (category or b"").decode(), text))

        self._logger = _Logger(log)  # kept: the FMU calls it for as long as the instance lives
        libc = ctypes.CDLL(None)
        self._callbacks = _Callbacks(self._logger, ctypes.cast(libc.calloc, ctypes.c_void_p).value,
                                     ctypes.cast(libc.free, ctypes.c_void_p).value, None, None)
        uri = "file://" + os.path.join(self._dir, "resources")
        self._c = self._lib.fmi2Instantiate(name.encode(), _CO_SIMULATION, self.guid.encode(), uri.encode(),
                                            ctypes.byref(self._callbacks), 0, 1 if logging else 0)
        if not self._c:
            raise FmuError("fmi2Instantiate: " + self._last_message("refused"))

    # -- calls ----------------------------------------------------------------------------------
    def _last_message(self, default):
        return self.messages[-1][2] if self.messages else default

    def _check(self, status, call, logged_before=None):
        """Raises FmuError for a refused call, with what the FMU logged during it (logged_before:
        the number of messages before the call)."""
        if status not in (_OK, _WARNING):
            fresh = self.messages[logged_before:] if logged_before is not None else self.messages[-1:]
            said = fresh[-1][2] if fresh else "%s returned %s" % (call, _STATUS[status] if 0 <= status < 6 else status)
            raise FmuError(said)

    def _call(self, name, *args):
        before = len(self.messages)
        self._check(getattr(self._lib, name)(self._c, *args), name, before)

    def _var(self, name):
        try:
            return self.variables[name]
        except KeyError:
            raise FmuError("the FMU has no variable %r (it has %s)" % (name, ", ".join(sorted(self.variables)))) from None

    def set(self, **values):
        """Set variables by name: inputs at any time, parameters before initialization ends."""
        for name, value in values.items():
            v = self._var(name)
            ref = (ctypes.c_uint * 1)(v.vr)
            if v.type == "Real":
                self._call("fmi2SetReal", ref, 1, (ctypes.c_double * 1)(value))
            elif v.type == "Integer":
                self._call("fmi2SetInteger", ref, 1, (ctypes.c_int * 1)(int(value)))
            else:
                raise FmuError("variable %r is a %s: this importer sets Real and Integer variables" % (name, v.type))

    def get(self, name):
        v = self._var(name)
        ref = (ctypes.c_uint * 1)(v.vr)
        if v.type == "Real":
            out = (ctypes.c_double * 1)()
            self._call("fmi2GetReal", ref, 1, out)
        elif v.type == "Integer":
            out = (ctypes.c_int * 1)()
            self._call("fmi2GetInteger", ref, 1, out)
        else:
            raise FmuError("variable %r is a %s: this importer reads Real and Integer variables" % (name, v.type))
        return out[0]

    def initialize(self, start_time=0.0, **values):
        """Set up the experiment, set parameters and inputs (by name), and end initialization."""
        self._call("fmi2SetupExperiment", 0, 0.0, start_time, 0, 0.0)
        self._call("fmi2EnterInitializationMode")
        self.set(**values)
        self._call("fmi2ExitInitializationMode")
        self.time, self._initialized = start_time, True

    def set_input_derivatives(self, name, *derivatives):
        """The input's first (and second) time derivative over the next step."""
        v = self._var(name)
        n = len(derivatives)
        refs, orders = (ctypes.c_uint * n)(*[v.vr] * n), (ctypes.c_int * n)(*range(1, n + 1))
        self._call("fmi2SetRealInputDerivatives", refs, n, orders, (ctypes.c_double * n)(*derivatives))

    def do_step(self, h, t=None):
        t = self.time if t is None else t
        self._call("fmi2DoStep", t, h, 1)
        self.time = t + h

    def simulate(self, x, h=1e-3, input="x", output="F", **parameters):
        """Initialize at x[0] with the parameters given, then one step of h per further input;
        the output after each (a list)."""
        x = [float(v) for v in x]
        self.initialize(**parameters, **{input: x[0]})
        out = [self.get(output)]
        for v in x[1:]:
            self.set(**{input: v})
            self.do_step(h)
            out.append(self.get(output))
        return out

    # -- state ----------------------------------------------------------------------------------
    def get_state(self, into=None):
        """The instance's state (fmi2GetFMUstate); into: a state of this instance to overwrite."""
        h = ctypes.c_void_p(into.handle if into is not None else None)
        self._call("fmi2GetFMUstate", ctypes.byref(h))
        if into is not None:
            into.time = self.time
            return into
        s = FmuState(self, h.value, self.time)
        self._states.add(s)
        return s

    def set_state(self, state):
        """Back to a state: the FMU's memory, input and time (the next do_step starts there)."""
        self._call("fmi2SetFMUstate", state.handle)
        self.time = state.time

    def serialize(self, state):
        size = ctypes.c_size_t()
        self._call("fmi2SerializedFMUstateSize", state.handle, ctypes.byref(size))
        buf = ctypes.create_string_buffer(size.value)
        self._call("fmi2SerializeFMUstate", state.handle, buf, size.value)
        return buf.raw

    def deserialize(self, data, time=None):
        """A state from serialize()'s bytes (of this FMU); time: the simulation time it holds."""
        h = ctypes.c_void_p()
        self._call("fmi2DeSerializeFMUstate", bytes(data), len(data), ctypes.byref(h))
        s = FmuState(self, h.value, self.time if time is None else time)
        self._states.add(s)
        return s

    # -- lifetime -------------------------------------------------------------------------------
    def close(self):
        if self._c:
            for s in list(self._states):
                s.free()
            if self._initialized:
                self._lib.fmi2Terminate(self._c)
            self._lib.fmi2FreeInstance(self._c)
            self._c = None
        shutil.rmtree(self._dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: nothing left to report to
            pass
