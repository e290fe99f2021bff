-- a string built from 3000 numbers, right to left
main = putStrLn (foldr (\x s -> show x ++ "," ++ s) "" [1 .. 3000])
