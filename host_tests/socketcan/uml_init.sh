#!/bin/sh
# PID 1 of the User-Mode Linux guest: brings up a virtual CAN bus, runs the
# test driver and hands its exit status back as the guest's own.
#   CDCR_TEST_DRIVER  the script to run; the other CDCR_* variables pass through.
export PATH=/usr/sbin:/usr/bin:/sbin:/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev 2>/dev/null

status=1
modules=/usr/lib/uml/modules/$(uname -r)/kernel
if insmod "$modules/net/can/can.ko" &&
  insmod "$modules/net/can/can-raw.ko" &&
  insmod "$modules/drivers/net/can/dev/can-dev.ko" &&
  insmod "$modules/drivers/net/can/vcan.ko" &&
  ip link add dev vcan0 type vcan && ip link set up vcan0; then
  # Room for frames while the guest's CPU falls behind for a moment on a
  # busy host: vcan hands every frame to the receive backlog (1000 frames by
  # default), which drops it for every listener, candump and the runtime
  # alike, when full; a full transmit queue refuses cansend (ENOBUFS).
  echo 100000 > /proc/sys/net/core/netdev_max_backlog
  ip link set vcan0 txqueuelen 10000
  sh "$CDCR_TEST_DRIVER"
  status=$?
else
  echo "uml-init: could not bring up vcan0 (modules of $(uname -r))"
fi

echo "$status" > /proc/exitcode
sync
echo o > /proc/sysrq-trigger
sleep 10
