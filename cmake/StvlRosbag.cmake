# stvl::rosbag: Debian 12's ROS 1 bag storage (librosbag-storage-dev 1.15) and message headers.
# pkg-config and the catkin configs are broken for this use, so the pieces are found by hand. Link it PRIVATE:
# only the .cpp behind the bag writer's pimpl includes ROS headers.
include_guard(GLOBAL)

find_package(Boost REQUIRED)

find_path(STVL_ROSBAG_INCLUDE_DIR rosbag/bag.h)
find_path(STVL_ROS_MSGS_INCLUDE_DIR sensor_msgs/PointCloud2.h)
foreach(header tf2_msgs/TFMessage.h nav_msgs/Odometry.h nav_msgs/OccupancyGrid.h nav_msgs/Path.h
               geometry_msgs/PoseStamped.h geometry_msgs/Twist.h)
  if(NOT EXISTS ${STVL_ROS_MSGS_INCLUDE_DIR}/${header})
    message(FATAL_ERROR "StvlRosbag: ${header} not found; run scripts/install-deps.sh")
  endif()
endforeach()

set(stvl_rosbag_libraries "")
foreach(lib rosbag_storage roscpp_serialization rostime cpp_common console_bridge)
  find_library(STVL_ROS_${lib}_LIBRARY NAMES ${lib})
  if(NOT STVL_ROS_${lib}_LIBRARY)
    message(FATAL_ERROR "StvlRosbag: lib${lib} not found; run scripts/install-deps.sh (librosbag-storage-dev)")
  endif()
  list(APPEND stvl_rosbag_libraries ${STVL_ROS_${lib}_LIBRARY})
endforeach()
if(NOT STVL_ROSBAG_INCLUDE_DIR OR NOT STVL_ROS_MSGS_INCLUDE_DIR)
  message(FATAL_ERROR "StvlRosbag: rosbag/bag.h or sensor_msgs headers not found; run scripts/install-deps.sh")
endif()

# rosbag/bag.h includes pluginlib, which includes class_loader, ament_index_cpp, rcpputils and rcutils; Debian
# installs each one level down (/usr/include/NAME/NAME/...).
set(stvl_rosbag_include_dirs ${STVL_ROSBAG_INCLUDE_DIR} ${STVL_ROS_MSGS_INCLUDE_DIR})
foreach(sub pluginlib class_loader ament_index_cpp rcpputils rcutils)
  if(IS_DIRECTORY ${STVL_ROSBAG_INCLUDE_DIR}/${sub})
    list(APPEND stvl_rosbag_include_dirs ${STVL_ROSBAG_INCLUDE_DIR}/${sub})
  endif()
endforeach()
list(REMOVE_DUPLICATES stvl_rosbag_include_dirs)

if(NOT TARGET stvl::rosbag)
  add_library(stvl::rosbag INTERFACE IMPORTED GLOBAL)
  # SYSTEM: ROS and Boost headers are not warning-clean under -Wall -Wextra -Wpedantic.
  set_target_properties(stvl::rosbag PROPERTIES
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${stvl_rosbag_include_dirs}"
    INTERFACE_INCLUDE_DIRECTORIES "${stvl_rosbag_include_dirs}"
    INTERFACE_LINK_LIBRARIES "${stvl_rosbag_libraries};Boost::headers")
endif()
