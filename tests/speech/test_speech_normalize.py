"""Text normalisation by num2words and anyascii: the cases of issue 18."""

import warnings

import pytest

from facelib.errors import PronunciationWarning
from facelib.speech import pronounce, synthesize, timeline_from_text, tokenize
from facelib.speech.normalize import num2words_language, spell_numbers, to_ascii

pytestmark = pytest.mark.speech


def test_jose_is_transliterated_and_found_in_the_dictionary():
    assert tokenize("José") == ["jose"]
    assert pronounce("jose") == (("HH", "OW", "Z", "EY"), True)


def test_cafe_is_transliterated_and_found_in_the_dictionary():
    assert tokenize("a café.") == ["a", "cafe", "."]
    assert pronounce("cafe") == (("K", "AH", "F", "EY"), True)  # CMU's first entry


def test_2026_is_read_as_a_year_not_digit_by_digit():
    assert tokenize("In 2026") == ["in", "twenty", "twenty", "six"]
    assert spell_numbers("2026", lang="pt") == "dois mil e vinte e seis"
    assert spell_numbers("2026", lang="de") == "zweitausendsechsundzwanzig"


def test_mude_in_german_is_spoken_with_its_rounded_vowel():
    made = synthesize("müde", lang="de")
    phones = [p.label for p in made.timeline.phones if p.label != "SIL"]
    assert phones == ["m", "y\u02d0", "d", "\u0259"]  # m, long y, d, schwa
    assert [w.label for w in made.timeline.words if w.label != "SIL"] == ["müde"]


def test_numbers_follow_the_language():
    assert spell_numbers("3,5 und 1.000", lang="de") == "drei Komma fünf und eintausend"
    assert spell_numbers("the 3rd of 1,000", lang="en") == "the third of one thousand"
    assert spell_numbers("abc 12", lang="xx-unknown") == "abc 12"  # espeak reads it itself
    assert num2words_language("pt-br") == "pt_BR"
    assert num2words_language("en-us") == "en"


def test_to_ascii():
    assert to_ascii("Ærø naïve José") == "Aero naive Jose"


def test_words_spoken_as_spelt_are_named_in_a_warning():
    with pytest.warns(PronunciationWarning, match="'zorblat'"):
        timeline_from_text("The zorblat sat.")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PronunciationWarning)
        timeline_from_text("José had a café in 2026.")  # every word is in the dictionary
