"""The logs wing: representations as protobuf (``serialization.py``), MCAP files written and read back,
damaged ones included (``logfile.py``), what a program records (``recording.py``) and the black box
that keeps the last seconds of everything (``blackbox.py``)."""
