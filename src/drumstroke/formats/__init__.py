"""Every file format drumstroke reads or writes, in one place: one module a format, both directions.

The modules turn files into plain Python data and numpy arrays, and back; they know no
drumstroke type (recipes, trajectories and libraries map themselves to and from this plain
data), so every layer above can call them. Every writer is atomic: a crash mid-write leaves
the old file whole. Every reader names the file, and the line or key, of what it refuses.
Every CSV starts with its header line; what a header cannot say is in the JSON beside it.

========================  ==========================================================================
:mod:`.toml`              TOML files: recipes, palettes, sweeps, robot and listening-test configs
:mod:`.json`              JSON files: strokes, compositions, reports, a library's manifest
:mod:`.signal_csv`        a recorded signal, ``t,value`` rows (a thumb-force recording)
:mod:`.trajectory_csv`    trajectories of one stick (``t,theta,omega``), several, or a kit's joints
:mod:`.sidecar`           the JSON beside a CSV: its version, model, name, rate, units, sticks
:mod:`.table`             tables of results (a sweep's) as CSV or parquet
:mod:`.midi`              Standard MIDI Files: notes read from scores, impacts written as notes
:mod:`.onsets_csv`        a recording's onsets, ``t,level_db`` rows (the impacts found in audio)
:mod:`.wav`               WAV audio
:mod:`.ros_json`          ROS 2 ``trajectory_msgs/JointTrajectory`` as JSON, and its metadata sidecar
:mod:`.rosbag`            a ROS 2 bag (rosbag2, MCAP or SQLite 3) of one ``JointTrajectory``
========================  ==========================================================================
"""
