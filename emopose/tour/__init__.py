"""The guided laboratory tour (paper: "Integrated laboratory-tour demonstration").

Scenario:   scenario.py (pydantic schema, conf/tour/*.yaml), scenario_checks.py (names, reachability)
Navigation: geometry.py, controller.py (turn-drive-turn on odometry), navigator.py (MobileBase, legs),
            sim_base.py (MuJoCo planar base + noisy odometry), g1_base.py (LocoClient + onboard odometry)
Talking:    voice.py (plan + speak a line, cut short), interruptions.py (scripted/live questions, intents),
            camera.py (head camera PNG for camera-grounded answers)
Pointing:   scene_view.py (what a pointing record refers to), pointing_ik.py (DLS IK), aim.py (the stage)
Running:    world.py (one control period at a time), runner.py (the tour), report.py, sim_scene.py
            (objects in the MJCF), job.py (+experiment=tour_lab), pointing_eval.py (+experiment=pointing_eval)
Importing this package imports neither mujoco nor cyclonedds.
"""
