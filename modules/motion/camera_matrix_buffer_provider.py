"""CameraMatrixBufferProvider: the camera matrices of the last motion frames, for cognition.

An image reaches cognition 30 to 40 ms after it was taken; by then the head may have turned several
degrees. Cognition therefore gets the recent history of both camera matrices with their times and
uses the pose that belongs to each image's time (``CameraMatrixBuffer.at``), as NaoTH's
CameraMatrixBuffer does.
"""

from __future__ import annotations

from tafel.core import Module, provides, requires
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import CAMERA_MATRIX_HISTORY, CameraMatrixBottom, CameraMatrixBuffer, CameraMatrixTop


@requires(FrameInfo, CameraMatrixTop, CameraMatrixBottom)
@provides(CameraMatrixBuffer)
class CameraMatrixBufferProvider(Module):
    """Appends this frame's camera matrices, dropping the oldest when the buffer is full."""

    frame_info: FrameInfo
    camera_matrix_top: CameraMatrixTop
    camera_matrix_bottom: CameraMatrixBottom
    camera_matrix_buffer: CameraMatrixBuffer

    def execute(self) -> None:
        if not (self.camera_matrix_top.valid and self.camera_matrix_bottom.valid):
            return
        buffer = self.camera_matrix_buffer
        now = self.frame_info.time_ns
        count = buffer.count
        if count and now <= int(buffer.time_ns[count - 1]):  # time went back (a log started over): start anew
            count = 0
        times, top_r, top_t = buffer.time_ns.copy(), buffer.top_rotation.copy(), buffer.top_translation.copy()
        bottom_r, bottom_t = buffer.bottom_rotation.copy(), buffer.bottom_translation.copy()
        if count == CAMERA_MATRIX_HISTORY:
            for array in (times, top_r, top_t, bottom_r, bottom_t):
                array[:-1] = array[1:]
            count -= 1
        times[count] = now
        top_r[count], top_t[count] = self.camera_matrix_top.rotation, self.camera_matrix_top.translation
        bottom_r[count], bottom_t[count] = self.camera_matrix_bottom.rotation, self.camera_matrix_bottom.translation
        buffer.time_ns, buffer.top_rotation, buffer.top_translation = times, top_r, top_t
        buffer.bottom_rotation, buffer.bottom_translation = bottom_r, bottom_t
        buffer.count = count + 1
