"""Stand-ins for hardware, for tests and benchmarks only; nothing in the runtime imports this package.

fake_robot: a fake Unitree G1 as its own process on DDS (`python -m emopose.testing.fake_robot`):
rt/lowstate out, rt/arm_sdk in (CRC-checked), and fake_loco, its locomotion RPC service.
"""
