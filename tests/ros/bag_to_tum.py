#!/usr/bin/python3
# Poses of a recorded nav_msgs/Odometry topic as a TUM trajectory (header stamp, position, orientation x y z w),
# and how many there were. Usage: bag_to_tum.py BAG TOPIC OUT.txt
import sys

import rosbag

bag, topic, out = sys.argv[1:4]
n = 0
with rosbag.Bag(bag) as b, open(out, "w") as f:
    for _, m, _ in b.read_messages(topics=[topic]):
        p, q = m.pose.pose.position, m.pose.pose.orientation
        f.write("%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n" % (m.header.stamp.to_sec(), p.x, p.y, p.z, q.x, q.y, q.z, q.w))
        n += 1
print(n)
