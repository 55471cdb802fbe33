"""control.command_inbox.CommandInbox: a queue of one between the thread a command arrives on and the loop."""
import threading

from diffbot_sim.control.command_inbox import CommandInbox


def test_the_newest_command_replaces_one_not_yet_taken_and_take_empties_it():
    inbox = CommandInbox()
    assert inbox.take() is None
    inbox.put((0.1, 0.0))
    inbox.put((0.2, 0.5))
    assert inbox.take() == (0.2, 0.5)
    assert inbox.take() is None


def test_each_put_wakes_the_loop():
    wake = threading.Event()
    inbox = CommandInbox(wake.set)
    inbox.put((0.0, 0.0))  # a zero command is a command
    assert wake.is_set() and inbox.take() == (0.0, 0.0)


def test_clear_forgets_a_command_not_yet_taken():
    inbox = CommandInbox()
    inbox.put([1.0, 2.0])
    inbox.clear()
    assert inbox.take() is None


def test_puts_from_another_thread_are_all_seen_or_replaced_never_lost_mid_way():
    inbox, seen = CommandInbox(), []

    def sender():
        for k in range(2000):
            inbox.put(k)
    thread = threading.Thread(target=sender)
    thread.start()
    while thread.is_alive():
        value = inbox.take()
        if value is not None:
            seen.append(value)
    thread.join()
    last = inbox.take()
    if last is not None:
        seen.append(last)
    assert seen == sorted(seen) and seen[-1] == 1999  # in order, the newest always arrives
