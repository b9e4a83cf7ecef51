"""The guided laboratory tour (paper: "Integrated laboratory-tour demonstration").

Scenario:   scenario.py (pydantic schema, conf/tour/*.yaml), scenario_loading.py (read + check a file),
            scenario_checks.py (names, reachability)
Navigation: controller.py (turn-drive-turn on odometry), navigator.py (MobileBase, legs), sim_base.py
            (MuJoCo planar base + noisy odometry), g1_base.py (LocoClient + onboard odometry); the base
            is the tour/base config group (conf/tour/base/); planar geometry is emopose/scene/geometry.py
Talking:    voice.py (plan + speak a line), interruptions.py (scripted/live questions, intents),
            camera.py (head camera PNG for camera-grounded answers)
Pointing:   emopose/scene/view.py (what a pointing record refers to), emopose/robot/pointing_ik.py
            (DLS IK), emopose/stages/aim.py (the stage)
Running:    world.py (one control period at a time), runner.py (the tour), report.py, sim_scene.py
            (objects in the MJCF), job.py (+experiment=tour_lab), pointing_eval.py (+experiment=pointing_eval)
Importing this package imports neither mujoco nor cyclonedds.
"""
