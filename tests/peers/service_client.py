"""The client side of a ROS 2 service over Cyclone DDS with the basic mapping: a request writer and
a reply reader, replies matched to requests by the sequence number in their header. Shared by
trajectory_peer.py and validity_peer.py."""

import time


class Client:
    def __init__(self, request_writer, reply_reader, make_request):
        """`make_request(x, seq)` builds the request sample for `x` with sequence number `seq`."""
        self.request_writer = request_writer
        self.reply_reader = reply_reader
        self.make_request = make_request
        self.seq = 0

    def send(self, x):
        """Writes the request for `x`; returns its sequence number."""
        self.seq += 1
        self.request_writer.write(self.make_request(x, self.seq))
        return self.seq

    def wait_answer(self, k, wait):
        """The reply to request `k`, or None after `wait` seconds (replies to others are dropped)."""
        stop = time.time() + wait
        while time.time() < stop:
            for x in self.reply_reader.take(N=10):
                if int(x.seq) == k:
                    return x
            time.sleep(0.005)
        return None
