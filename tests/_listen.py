"""A small listening test for the app's tests: rendered stimuli, a config, a store and a running server."""

import threading

from drumstroke.evaluation.app import Config, Store, make_server
from drumstroke.render.audio import render_wav


def start_test(folder, *, pairs, token, seed):
    """Write stimuli and a config into ``folder``, serve it on a free loopback port; (base URL, config, store, server)."""
    for i in range(pairs):
        for side, speed in (("human", 1.0), ("robot", 0.7)):
            render_wav(folder / f"{side}-{i}.wav", [0.01, 0.12], [speed, 0.5 * speed], duration=0.3)
    tables = "".join(f'[[pair]]\nid = "p{i}"\nhuman = "human-{i}.wav"\nrobot = "robot-{i}.wav"\n' for i in range(pairs))
    (folder / "test.toml").write_text(f'title = "Robot or human?"\nadmin_token = "{token}"\nseed = {seed}\n{tables}')
    config = Config.from_toml(folder / "test.toml")
    store = Store(folder / "results.sqlite")
    server = make_server(config, store, port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return f"http://127.0.0.1:{server.server_address[1]}", config, store, server


def stop(server):
    server.shutdown()
    server.server_close()
