-- fuzz case: dm.tableau(0/0): invalid option '-nan'
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.tableau"](H["nan"])
end
