"""The kit: the pieces a drummer's limbs play, the pedals the feet work, and which limb plays each note.

- :mod:`.pieces`: :class:`~.pieces.Piece` and :class:`~.pieces.Kit`, the kit's description (each piece's
  MIDI keys, limbs, place, h below the fulcrum, c and sound; the hands' positioning joints' limits),
  read from a TOML file a person writes (:func:`~.pieces.read_kit`), the shipped five-piece
  :func:`~.pieces.default_kit`, and each piece's :class:`~drumstroke.design.Setup`.
- :mod:`.limbs`: :func:`~.limbs.assign_limbs`, the limb of each note of a part that names none, as a
  drummer assigns them: an exact dynamic programme over the notes (travel within the joints' limits,
  repeats, the lead hand keeping time, the backbeat, crossing), the unplayable reported.
- :mod:`.play`: :func:`~.play.play_hands`, the hands' performance of a part: each hand's notes as runs on
  one piece planned by the one-stick planner on that piece's setup, joined by synchronised, jerk-limited
  moves of all its joints (its positioning joints and the stick's angle) that keep the stick clear of
  the surfaces it passes over; each hand's motion one multi-joint curve, every note played or reported.
- :mod:`.pedal`: the kick's beater (and the hi-hat's pedal): a rod about the pedal's axle striking a
  vertical head, driven by the foot against the pedal's spring; the same kind of exact hybrid system as
  the stick (flight, impact with restitution, rest), and its inverse: :class:`~.pedal.Pedal`,
  :func:`~.pedal.simulate_pedal` (foot force -> exact motion), :func:`~.pedal.design_pedal` (notes -> foot force).
"""
