"""RobotControl in the browser: the page the program serves, and what feeds it."""

from tafel.tools.viewers.web.view import STATIC, WebView, web_topics

__all__ = ["STATIC", "WebView", "web_topics"]
