"""robocfg.collision.shapes: robot geometry attached to the right pinocchio frames."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from robocfg.collision.shapes import LinkGeometry, add_robot_geometry

# a revolute joint, then a fixed joint named like the link it carries (the Unitree Z1's gripperStator)
URDF = """<robot name="r">
  <link name="base"/>
  <link name="arm"/>
  <link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="tip" type="fixed"><parent link="arm"/><child link="tip"/><origin xyz="0.3 0 0"/></joint>
</robot>"""


def test_geometry_goes_to_the_link_frame_when_a_joint_has_the_same_name():
    model = pin.buildModelFromXML(URDF)
    assert model.existFrame("tip", pin.FrameType.BODY) and model.existFrame("tip", pin.FrameType.FIXED_JOINT)
    geom = pin.GeometryModel()
    assert add_robot_geometry(geom, model, [LinkGeometry("tip", "sphere", np.eye(4), (0.02,))]) == 1
    data, gdata = model.createData(), pin.GeometryData(geom)
    pin.updateGeometryPlacements(model, data, geom, gdata, np.array([np.pi / 2]))
    assert np.allclose(gdata.oMg[0].translation, [0.0, 0.3, 0.0], atol=1e-9)  # turned with j1, 0.3 m out
