"""``deferred view``: the interactive viewer (moderngl-window, imgui-bundle).

One module a responsibility: :mod:`~deferred.viewer.app` the viewer's state, its frames and
actions; :mod:`~deferred.viewer.window` the window and its loop; :mod:`~deferred.viewer.input`
the mouse and the keys; :mod:`~deferred.viewer.camera` the orbit / pan / zoom / fly
controller; :mod:`~deferred.viewer.session` the scene, its validated edits and saving them;
:mod:`~deferred.viewer.panels` the imgui panels (drawn by :mod:`~deferred.viewer.imgui_gl`);
:mod:`~deferred.viewer.display` the viewport (single, split, difference);
:mod:`~deferred.viewer.compare` the split's PSNR; :mod:`~deferred.viewer.buffers` the buffer
view; :mod:`~deferred.viewer.inspector` the pixel inspector; :mod:`~deferred.viewer.timeline`
the clock; :mod:`~deferred.viewer.reload` hot reload; :mod:`~deferred.viewer.record`
screenshots and recordings; :mod:`~deferred.viewer.renderers` the renderers on the window's
context.
"""
