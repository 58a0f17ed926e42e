"""piezoshift: the piezo-actuated phase shifter's design, digital twin, calibration and
experiments, from Python (docs/python.md).

Everything is re-exported from the compiled extension ``piezoshift._piezoshift``. Value structs
have the C++ field names (units in every name); time series are numpy arrays.
"""

from ._piezoshift import *  # noqa: F401,F403
# the exception types are not always picked up by the star import
from ._piezoshift import InputError, FitError, MetricsError, ProcedureFailed  # noqa: F401
from ._piezoshift import StageFault, StageTimeout  # noqa: F401
from . import _piezoshift as _ext
import inspect as _inspect

__all__ = [name for name in dir(_ext) if not name.startswith("_")]
__version__ = "0.1.0"



def _fields(obj):
    """The names of a bound struct's fields, in declaration order."""
    return [name for name, v in vars(type(obj)).items()
            if isinstance(v, property) and not name.startswith("_")]


def _repr(obj):
    parts = []
    for name in _fields(obj):
        value = getattr(obj, name)
        if hasattr(value, "shape") and value.size > 9:
            parts.append(f"{name}=<array {value.shape}>")
        else:
            parts.append(f"{name}={value!r}")
    return f"{type(obj).__name__}({', '.join(parts)})"


def to_dict(obj):
    """A bound struct as nested dicts (numpy arrays as lists), e.g. for json.dumps."""
    if hasattr(obj, "tolist"):
        return obj.tolist()
    if isinstance(obj, (list, tuple)):
        return [to_dict(v) for v in obj]
    if hasattr(type(obj), "__members__"):  # a bound enum
        return obj.name
    fields = _fields(obj) if type(obj).__module__.startswith("piezoshift") else []
    if not fields:
        return obj
    return {name: to_dict(getattr(obj, name)) for name in fields}


def _keyword_init(cls):
    """Lets cls(field=value, ...) set fields after the C++ constructor (positional arguments go
    to it unchanged), with a signature that names every field and its default."""
    fields = [name for name, v in vars(cls).items()
              if isinstance(v, property) and v.fset is not None and not name.startswith("_")]
    if not fields:
        return
    try:
        default = cls()
    except TypeError:  # no default constructor: not a parameter struct
        return
    original = cls.__init__

    def __init__(self, *args, **kwargs):
        original(self, *args)
        for name, value in kwargs.items():
            if name not in fields:
                raise TypeError("%s() got an unexpected keyword argument %r; its fields: %s"
                                % (cls.__name__, name, ", ".join(fields)))
            setattr(self, name, value)

    kw = _inspect.Parameter.KEYWORD_ONLY
    __init__.__signature__ = _inspect.Signature(
        [_inspect.Parameter("self", _inspect.Parameter.POSITIONAL_OR_KEYWORD)]
        + [_inspect.Parameter(f, kw, default=getattr(default, f)) for f in fields])
    __init__.__doc__ = ("%s(*, %s): the C++ defaults (the paper's values), with any field given "
                        "by keyword.\n\n%s" % (cls.__name__, ", ".join(fields),
                                                original.__doc__ or ""))
    cls.__init__ = __init__


# Every bound struct prints its fields and takes its fields as keyword arguments; enums keep
# pybind11's own repr.
for _cls in vars(_ext).values():
    if isinstance(_cls, type) and not hasattr(_cls, "__members__") and not issubclass(
            _cls, BaseException):
        _cls.__repr__ = _repr
        _keyword_init(_cls)
del _cls
__all__.append("to_dict")
