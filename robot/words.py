"""Names of the project's things in a user's words, for messages and plot captions:
limbs (``left_hand`` → left hand), hold targets and ladder pieces (``rail_left`` → the
left rail), collision objects (``L_shin/0`` → the left shin) and joints (``LKN`` → LKN
(left knee))."""

from __future__ import annotations

from robot.vocabulary import Limb

#: Words for the joint-name suffixes of the 40-column file (``LKN`` → left knee).
JOINT_WORDS = {"HY": "hip yaw", "HR": "hip roll", "HP": "hip pitch", "KN": "knee",
               "AP": "ankle pitch", "AR": "ankle roll", "SP": "shoulder pitch",
               "SR": "shoulder roll", "SY": "shoulder yaw", "EB": "elbow", "WY": "wrist yaw",
               "WR": "wrist roll", "WP": "wrist pitch", "ST": "waist"}


def limb_words(limb: str) -> str:
    """``left_hand`` → ``left hand``."""
    return str(Limb(limb)).replace("_", " ")


def target_words(target: str) -> str:
    """A hold target or ladder piece in words: ``rung_0`` → ``rung 0``, ``rail_left`` →
    ``the left rail``, ``stringer_right`` → ``the right stringer``, ``floor`` → ``the
    floor``."""
    words = target.split("_")
    if words[0] == "rung":
        return f"rung {words[1]}"
    if words[-1] in ("left", "right"):
        return f"the {words[-1]} {' '.join(words[:-1])}"
    return "the " + " ".join(words)


def part_words(name: str) -> str:
    """A collision object in words: a robot part (``L_shin/0`` → ``the left shin``,
    ``R_finger3/1`` → ``the right finger``) or a ladder piece (`target_words`)."""
    if "/" not in name:
        return target_words(name)
    link = name.split("/")[0].rstrip("0123456789")
    side, _, rest = link.partition("_")
    if side in ("L", "R") and rest:
        return f"the {'left' if side == 'L' else 'right'} {rest.replace('_', ' ')}"
    return "the " + link.replace("_", " ")


def joint_words(joint: str) -> str:
    """``LKN`` → ``LKN (left knee)``; a name without a known suffix stays as it is."""
    side = {"L": "left ", "R": "right "}.get(joint[:1], "")
    what = JOINT_WORDS.get(joint[1:] if side else joint[-2:])
    return f"{joint} ({side}{what})" if what else joint
