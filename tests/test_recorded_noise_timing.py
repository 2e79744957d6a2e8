"""The template's own start in noise (onsets' ``_attack_sound``, ``OnsetConfig.template_start_db`` and
``template_start_past_db``).

Step 5 times every attack over earlier sound by the recording's own attack: the template is the band from 0.5 ms
before its loudest clear attack's detected time, and an attack fitted by it is put at the template's start. Where
that detection is late, every attack the template times inherits the delay. TimGM6mb's snare 40 rises in two steps,
a lead-in at 2-4 % of its peak and its main rise 1 ms later; at -60 dBFS noise (some -50 dB re the loud note, its
largest samples over 5 ms at -40 dB) the stages before step 5 detect the note on its main rise, 1.2 ms late on the
corpus's seed 2 (0.47 ms on seed 0), and the drop's bounces, all template-timed, were all 1.0-1.2 ms late. The
template's start is now found on the template's own samples: the first sample up to 2 ms before the detection over
-40 dB re its peak (the truth's own rule) and 1.5 times the largest magnitude over the 5 ms before (the noise).
``template_start_db=0`` gives the start where it was detected, as before.
"""

from _recorded_drums import RATE, recording, score
from drumstroke.analysis import OnsetConfig, find_onsets


def test_a_drops_template_timed_bounces_are_not_late_in_noise():
    """TimGM6mb's snare 40 drop at -60 dBFS noise, seed 2: 56 loud notes, 4 within 1 ms before (every bounce
    the template timed 1.02-1.20 ms late), 55 now, all 56 within 5 ms either way and no false detection more;
    ``template_start_db=0`` (the start where it was detected, as before) gives the earlier onsets."""
    truth = recording("TimGM6mb", 40, "drop", "noise60", seed=2)
    now = score(truth, find_onsets(truth.signal, RATE).t)
    then = score(truth, find_onsets(truth.signal, RATE, config=OnsetConfig(template_start_db=0.0)).t)
    assert then["within_1ms"] <= 10 and now["within_1ms"] >= then["within_1ms"] + 45
    assert now["correct_5ms"] >= then["correct_5ms"]
    assert now["found"] - now["correct_5ms"] <= then["found"] - then["correct_5ms"]


def test_a_detection_in_the_noise_before_the_template_does_not_stop_its_start():
    """TimGM6mb's snare 40 drop at -72 dBFS noise, seed 5: a detection in the noise 1.4 ms before the loudest clear
    note stopped its start being sought (``template_start_past_db=120``, as before), and 7 of its 53 loud notes were
    within 1 ms (the others 1.13 ms late), 52 within 5 ms; now 52 are within 1 ms and all 53 within 5 ms, and no
    false detection more."""
    truth = recording("TimGM6mb", 40, "drop", "noise72", seed=5)
    now = score(truth, find_onsets(truth.signal, RATE).t)
    then = score(truth, find_onsets(truth.signal, RATE, config=OnsetConfig(template_start_past_db=120.0)).t)
    assert then["within_1ms"] <= 10 and now["within_1ms"] >= 50
    assert now["correct_5ms"] >= then["correct_5ms"] and now["within_5ms"] == now["loud"]
    assert now["found"] - now["correct_5ms"] <= then["found"] - then["correct_5ms"]
