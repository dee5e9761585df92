"""Gear standards as shortcuts from what a drawing says to the model's numbers: ISO 1328-1:2013
flank tolerances of an accuracy class (``iso1328``) and a circumferential backlash band to the
half backlash of Eq. (6) (``backlash``). Each module cites the clause it implements and refuses
inputs outside the standard's range of validity."""
