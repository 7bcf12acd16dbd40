"""Measured records: reading (CSV, MAT), validation and explicit resampling.

A :class:`Record` is one experiment: time, the plant input (the command) and
the plant output (the measurement), with names and units, plus any extra
logged channels; a :class:`DisturbanceRecord` is one measured channel without an
input (for spectra). Files are read as they come (:mod:`synth.data.readers`:
comment lines, units in headers, MAT matrices and structs). Every problem with a
file is a :class:`~synth.errors.DataError` naming the file and column.
"""

from synth.data.coerce import RecordLike, as_record
from synth.data.disturbance import DisturbanceRecord, disturbance_from_arrays, load_disturbance
from synth.data.readers import Table, parse_column_map, read_table
from synth.data.record import Record, load_record, record_from_arrays, record_from_columns

__all__ = ["DisturbanceRecord", "Record", "RecordLike", "Table", "as_record", "disturbance_from_arrays",
           "load_disturbance", "load_record", "parse_column_map", "read_table", "record_from_arrays",
           "record_from_columns"]
