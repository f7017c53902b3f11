"""The process runtime: pinned numerics (:mod:`.numerics`, the libm probe
:mod:`.libm_probe`), native output hidden (:mod:`.quiet`), and interrupts (:mod:`.interrupts`).
Below every step of the method; imports nothing of rigidfold but its foundations."""
