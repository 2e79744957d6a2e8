"""The kit: the pieces a drummer's limbs play, the pedals the feet work, and which limb plays each note.

- :mod:`.pedal`: the kick's beater (and the hi-hat's pedal): a rod about the pedal's axle striking a
  vertical head, driven by the foot against the pedal's spring; the same kind of exact hybrid system as
  the stick (flight, impact with restitution, rest), and its inverse: :class:`~.pedal.Pedal`,
  :func:`~.pedal.simulate_pedal` (foot force -> exact motion), :func:`~.pedal.design_pedal` (notes -> foot force).
"""
