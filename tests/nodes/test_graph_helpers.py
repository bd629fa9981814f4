"""The tests' service call sends an unanswered request again, as the supervisor retries: the
middleware may drop a fresh client's first reply (docs/reliability.md)."""
import pytest

from graph_helpers import call


class Future:
    def __init__(self, answered: bool, value):
        self.answered, self.value = answered, value

    def done(self) -> bool:
        return self.answered

    def result(self):
        return self.value


class Client:
    """A ready server that drops the replies to the first DROPPED requests."""
    srv_name = "/fake/set_weights"

    def __init__(self, dropped: int):
        self.dropped, self.sent = dropped, []

    def service_is_ready(self) -> bool:
        return True

    def call_async(self, request):
        self.sent.append(request)
        return Future(len(self.sent) > self.dropped, f"reply to {request} #{len(self.sent)}")


class Executor:
    def spin_once(self, timeout_sec: float) -> None:
        pass


def test_a_dropped_reply_is_asked_for_again_and_the_first_reply_taken():
    client = Client(dropped=2)
    assert call(Executor(), client, "req", timeout=5.0, resend_sec=0.05) == "reply to req #3"
    assert client.sent == ["req"] * 3


def test_an_answered_request_is_sent_once():
    client = Client(dropped=0)
    assert call(Executor(), client, "req", timeout=5.0, resend_sec=0.05) == "reply to req #1"
    assert client.sent == ["req"]


def test_a_server_that_never_answers_fails_the_test_after_the_timeout():
    client = Client(dropped=10 ** 9)
    with pytest.raises(AssertionError, match="timed out waiting for reply from /fake/set_weights"):
        call(Executor(), client, "req", timeout=0.3, resend_sec=0.05)
    assert 2 <= len(client.sent) <= 8
